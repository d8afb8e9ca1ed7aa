// SPDX-License-Identifier: MIT
#include "line_session.hpp"

#include <array>

#include <boost/asio/buffer.hpp>
#include <boost/asio/write.hpp>

namespace turtlegas::server::detail {

namespace asio = boost::asio;

LineSession::LineSession(asio::ip::tcp::socket&& socket, WorldHost& host)
    : Session(socket.get_executor(), host), socket_(std::move(socket)) {
  boost::system::error_code ec;
  const auto peer = socket_.remote_endpoint(ec);
  loopback = !ec && peer.address().is_loopback();
  socket_.set_option(asio::ip::tcp::no_delay(true), ec);
  id = host.next_client_id();
}

void LineSession::run() {
  opened();
  read();
}

void LineSession::read() {
  socket_.async_read_some(asio::buffer(chunk_), [self = std::static_pointer_cast<LineSession>(shared_from_this())](
                                                    boost::system::error_code ec, std::size_t n) {
    if (ec) {
      self->gone();
      return;
    }
    self->take(self->chunk_.data(), n);
    self->read();
  });
}

void LineSession::take(const char* data, std::size_t n) {
  const std::size_t max = host_.options().limits.max_message;
  std::size_t begin = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (data[k] != '\n') continue;
    if (!discarding_) {
      line_.append(data + begin, k - begin);
      if (!line_.empty() && line_.back() == '\r') line_.pop_back();
      if (line_.size() > max) {
        refuse("too_large", "a line may have at most " + std::to_string(max) + " bytes; it was skipped");
      } else if (!line_.empty()) {
        received(line_);
      }
    }
    discarding_ = false;
    line_.clear();
    begin = k + 1;
  }
  if (discarding_) return;
  line_.append(data + begin, n - begin);
  if (line_.size() > max + 1) {  // + 1: room for a '\r' before the '\n'
    refuse("too_large", "a line may have at most " + std::to_string(max) + " bytes; it is skipped up to its end");
    discarding_ = true;
    line_.clear();
    line_.shrink_to_fit();
  }
}

void LineSession::start_write(const Out& out) {
  static const char newline = '\n';
  const std::array<asio::const_buffer, 2> buffers = {asio::buffer(*out.data), asio::buffer(&newline, 1)};
  asio::async_write(socket_, buffers,
                    [self = std::static_pointer_cast<LineSession>(shared_from_this())](boost::system::error_code ec, std::size_t n) {
                      self->written(!ec, n);
                    });
}

void LineSession::shut() {
  boost::system::error_code ec;
  socket_.shutdown(asio::ip::tcp::socket::shutdown_both, ec);
  socket_.close(ec);
}

}  // namespace turtlegas::server::detail
