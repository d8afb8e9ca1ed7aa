// SPDX-License-Identifier: MIT
// An HTTP connection (Beast): GET /, static files of the web root, /api/world, /api/state, and
// the WebSocket upgrade at /ws, which hands the socket to a WebSocketSession.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>

#include "turtlegas/server/world_host.hpp"

namespace turtlegas::server::detail {

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(boost::asio::ip::tcp::socket&& socket, WorldHost& host, std::filesystem::path web_root);
  void run();

 private:
  using Request = boost::beast::http::request<boost::beast::http::string_body>;
  using Response = boost::beast::http::response<boost::beast::http::string_body>;
  void read();
  void serve(Request req);
  void write(std::shared_ptr<Response> res);
  std::shared_ptr<Response> respond(const Request& req, boost::beast::http::status status, std::string body,
                                    const char* type);

  boost::beast::tcp_stream stream_;
  boost::beast::flat_buffer buffer_;
  std::optional<boost::beast::http::request_parser<boost::beast::http::string_body>> parser_;
  WorldHost& host_;
  std::filesystem::path web_root_;
  bool loopback_ = true;
};

}  // namespace turtlegas::server::detail
