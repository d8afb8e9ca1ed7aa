// SPDX-License-Identifier: MIT
#include "websocket_session.hpp"

#include <boost/asio/buffer.hpp>

namespace turtlegas::server::detail {

namespace beast = boost::beast;
namespace websocket = beast::websocket;

WebSocketSession::WebSocketSession(boost::asio::ip::tcp::socket&& socket, WorldHost& host)
    : Session(socket.get_executor(), host), ws_(std::move(socket)) {
  boost::system::error_code ec;
  const auto peer = ws_.next_layer().socket().remote_endpoint(ec);
  loopback = !ec && peer.address().is_loopback();
  id = host.next_client_id();
}

void WebSocketSession::run(const beast::http::request<beast::http::string_body>& req) {
  // Results and frames go out as soon as they are written (as on TCP lines): no Nagle delay for a
  // lockstep client's next round trip.
  boost::system::error_code nodelay_ec;  // (a socket that will not take it just keeps Nagle)
  ws_.next_layer().socket().set_option(boost::asio::ip::tcp::no_delay(true), nodelay_ec);
  ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
  ws_.read_message_max(host_.options().limits.max_websocket_read);
  ws_.auto_fragment(false);  // a frame goes out as one WebSocket frame
  ws_.async_accept(req, [self = std::static_pointer_cast<WebSocketSession>(shared_from_this())](beast::error_code ec) {
    if (ec) return;
    self->opened();
    self->read();
  });
}

void WebSocketSession::read() {
  ws_.async_read(buffer_, [self = std::static_pointer_cast<WebSocketSession>(shared_from_this())](beast::error_code ec, std::size_t) {
    if (ec) {
      self->gone();
      return;
    }
    if (self->ws_.got_text()) {
      const auto data = self->buffer_.cdata();
      self->received(std::string_view(static_cast<const char*>(data.data()), data.size()));
    } else {
      self->refuse("bad_json", "binary messages are not requests; send JSON text messages");
    }
    self->buffer_.consume(self->buffer_.size());
    self->read();
  });
}

void WebSocketSession::start_write(const Out& out) {
  ws_.binary(out.binary);
  ws_.async_write(boost::asio::buffer(*out.data),
                  [self = std::static_pointer_cast<WebSocketSession>(shared_from_this())](beast::error_code ec, std::size_t n) {
                    self->written(!ec, n);
                  });
}

void WebSocketSession::shut() {
  ws_.async_close(websocket::close_code::normal,
                  [self = std::static_pointer_cast<WebSocketSession>(shared_from_this())](beast::error_code) {});
}

}  // namespace turtlegas::server::detail
