// SPDX-License-Identifier: MIT
// A WebSocket connection at /ws (Beast): text messages in, replies and frames out.
#pragma once

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "session.hpp"

namespace turtlegas::server::detail {

class WebSocketSession : public Session {
 public:
  WebSocketSession(boost::asio::ip::tcp::socket&& socket, WorldHost& host);
  /// Accepts the upgrade request `req` (read by the HTTP session; the reply is built from it before
  /// this returns, so it need not outlive the call), then reads messages.
  void run(const boost::beast::http::request<boost::beast::http::string_body>& req);
  bool binary_capable() const override { return true; }

 private:
  void start_write(const Out& out) override;
  void shut() override;
  void read();

  boost::beast::websocket::stream<boost::beast::tcp_stream> ws_;
  boost::beast::flat_buffer buffer_;
};

}  // namespace turtlegas::server::detail
