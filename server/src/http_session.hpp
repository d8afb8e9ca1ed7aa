// SPDX-License-Identifier: MIT
// An HTTP connection (Beast): GET /, static files of the web root, /api/world, /api/state, and
// the WebSocket upgrade at /ws, which hands the socket to a WebSocketSession.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>

#include "turtlegas/server/world_host.hpp"

namespace turtlegas::server::detail {

/// Who may come in through HTTP (docs/protocol.md, "Who gets in"): every request's Host and a
/// WebSocket upgrade's Origin must name this server as a page of its own would (127.0.0.1,
/// localhost, [::1] or the bind address, with the HTTP port), or what --allow-origin allows. A
/// page elsewhere (a foreign Origin) or a name rebound to 127.0.0.1 (DNS rebinding: a foreign Host)
/// gets 403. A request without an Origin is not a page's: it is let in (the token still counts).
struct Door {
  std::vector<std::string> hosts;    ///< "host:port", lower case
  std::vector<std::string> origins;  ///< "http://host:port", lower case
  bool anyone = false;               ///< --allow-origin '*'
  bool allows_host(std::string_view host) const;
  bool allows_origin(std::string_view origin) const;
  /// The names it answers to, for the refusal's message.
  std::string names() const;
};
/// The door of a server bound to `bind` with HTTP port `port`, opened also to each origin of
/// `allowed` (--allow-origin: "http://name:port", or "*" for any).
Door make_door(const std::string& bind, unsigned short port, const std::vector<std::string>& allowed);

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(boost::asio::ip::tcp::socket&& socket, WorldHost& host, std::filesystem::path web_root,
              std::shared_ptr<const Door> door);
  ~HttpSession();
  HttpSession(const HttpSession&) = delete;
  HttpSession& operator=(const HttpSession&) = delete;
  void run();

 private:
  using Request = boost::beast::http::request<boost::beast::http::string_body>;
  using Response = boost::beast::http::response<boost::beast::http::string_body>;
  void read();
  void serve(Request req);
  void write(std::shared_ptr<Response> res);
  /// A static file, streamed from disk as the socket takes it (not read whole into memory).
  void write_file(const Request& req, const std::filesystem::path& file);
  /// After a response is written: the next request, or the connection shut.
  void written(boost::beast::error_code ec, bool keep_alive);
  std::shared_ptr<Response> respond(const Request& req, boost::beast::http::status status, std::string body,
                                    const char* type);

  boost::beast::tcp_stream stream_;
  boost::beast::flat_buffer buffer_;
  std::optional<boost::beast::http::request_parser<boost::beast::http::string_body>> parser_;
  WorldHost& host_;
  std::filesystem::path web_root_;
  std::shared_ptr<const Door> door_;
  bool loopback_ = true;
};

}  // namespace turtlegas::server::detail
