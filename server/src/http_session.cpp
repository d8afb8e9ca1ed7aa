// SPDX-License-Identifier: MIT
#include "http_session.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <string_view>
#include <tuple>

#include <boost/asio/ip/address.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/websocket.hpp>

#include "turtlegas/server/protocol.hpp"
#include "websocket_session.hpp"

namespace turtlegas::server::detail {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;

const char* content_type(const std::filesystem::path& p) {
  const std::string ext = p.extension().string();
  if (ext == ".html" || ext == ".htm") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json") return "application/json";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".png") return "image/png";
  if (ext == ".ico") return "image/x-icon";
  if (ext == ".wasm") return "application/wasm";
  if (ext == ".txt" || ext == ".md") return "text/plain; charset=utf-8";
  return "application/octet-stream";
}

constexpr std::string_view placeholder_page = R"(<!doctype html>
<html><head><meta charset="utf-8"><title>turtlegas serve</title></head>
<body><h1>turtlegas serve</h1>
<p>The viewer is not installed yet. The world is at <a href="/api/world">/api/world</a>, its current
state at <a href="/api/state">/api/state</a>; the protocol (WebSocket at <code>/ws</code>, or TCP
lines) is described in docs/protocol.md.</p></body></html>
)";

/// The file below root that `target` names, or nullopt: no "..", no hidden names, no symlink
/// leading out of the root.
std::optional<std::filesystem::path> static_file(const std::filesystem::path& root, std::string_view target) {
  if (target.empty() || target[0] != '/') return std::nullopt;
  std::string rel(target.substr(1));
  if (rel.empty()) rel = "index.html";
  if (rel.find('\\') != std::string::npos || rel.find('\0') != std::string::npos || rel.find('%') != std::string::npos) return std::nullopt;
  std::filesystem::path p;
  std::size_t begin = 0;
  while (begin <= rel.size()) {
    const std::size_t end = rel.find('/', begin);
    const std::string part = rel.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
    if (part.empty() || part[0] == '.') return std::nullopt;  // "", ".", "..", hidden
    p /= part;
    if (end == std::string::npos) break;
    begin = end + 1;
  }
  std::error_code ec;
  const std::filesystem::path canon_root = std::filesystem::weakly_canonical(root, ec);
  if (ec) return std::nullopt;
  const std::filesystem::path full = std::filesystem::weakly_canonical(root / p, ec);
  if (ec) return std::nullopt;
  const std::string r = canon_root.string() + "/", f = full.string();
  if (f.compare(0, r.size(), r) != 0) return std::nullopt;  // a symlink out of the root
  if (!std::filesystem::is_regular_file(full, ec)) return std::nullopt;
  return full;
}

std::string_view sv(beast::string_view v) { return {v.data(), v.size()}; }

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

bool Door::allows_host(std::string_view host) const {
  if (anyone || host.empty()) return true;  // no Host (HTTP/1.0): not a browser's request
  const std::string h = lower(host);
  return std::find(hosts.begin(), hosts.end(), h) != hosts.end();
}

bool Door::allows_origin(std::string_view origin) const {
  if (anyone) return true;
  const std::string o = lower(origin);
  return std::find(origins.begin(), origins.end(), o) != origins.end();
}

std::string Door::names() const {
  std::string out;
  for (const std::string& h : hosts) out += (out.empty() ? "" : ", ") + h;
  return out;
}

Door make_door(const std::string& bind, unsigned short port, const std::vector<std::string>& allowed) {
  Door d;
  const std::string p = ":" + std::to_string(port);
  std::vector<std::string> names = {"127.0.0.1", "localhost", "[::1]"};
  boost::system::error_code ec;
  const auto a = boost::asio::ip::make_address(bind, ec);
  if (!ec && !a.is_unspecified()) names.push_back(a.is_v6() ? "[" + a.to_string() + "]" : a.to_string());
  for (const std::string& n : names) {
    if (std::find(d.hosts.begin(), d.hosts.end(), n + p) != d.hosts.end()) continue;
    d.hosts.push_back(n + p);
    d.origins.push_back("http://" + n + p);
    if (port == 80) d.hosts.push_back(n);  // a browser leaves out the default port
  }
  for (const std::string& o : allowed) {
    if (o == "*") {
      d.anyone = true;
      continue;
    }
    const std::string l = lower(o);
    d.origins.push_back(l);
    const std::size_t scheme = l.find("://");
    if (scheme != std::string::npos) d.hosts.push_back(l.substr(scheme + 3));
  }
  return d;
}

HttpSession::HttpSession(boost::asio::ip::tcp::socket&& socket, WorldHost& host, std::filesystem::path web_root,
                         std::shared_ptr<const Door> door)
    : stream_(std::move(socket)), host_(host), web_root_(std::move(web_root)), door_(std::move(door)) {
  host_.http_opened();
  boost::system::error_code ec;
  const auto peer = stream_.socket().remote_endpoint(ec);
  loopback_ = !ec && peer.address().is_loopback();
}

HttpSession::~HttpSession() { host_.http_closed(); }

void HttpSession::run() { read(); }

void HttpSession::read() {
  parser_.emplace();
  parser_->body_limit(64 * 1024);
  parser_->header_limit(16 * 1024);
  stream_.expires_after(std::chrono::seconds(30));
  http::async_read(stream_, buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec == http::error::header_limit) {  // the request line counts: a huge URL lands here too
      Request req;
      req.version(11);
      req.keep_alive(false);
      return self->write(self->respond(req, http::status::request_header_fields_too_large,
                                       "the request line and headers may have at most 16 KiB\n", "text/plain"));
    }
    if (ec) {
      beast::error_code ignored;
      self->stream_.socket().shutdown(boost::asio::ip::tcp::socket::shutdown_both, ignored);
      return;
    }
    self->serve(self->parser_->release());
  });
}

std::shared_ptr<HttpSession::Response> HttpSession::respond(const Request& req, http::status status, std::string body,
                                                            const char* type) {
  auto res = std::make_shared<Response>(status, req.version());
  res->set(http::field::server, std::string(server_name));
  res->set(http::field::content_type, type);
  res->set(http::field::cache_control, "no-store");
  res->keep_alive(req.keep_alive());
  const bool head = req.method() == http::verb::head;
  res->body() = std::move(body);
  res->prepare_payload();
  if (head) res->body().clear();
  return res;
}

void HttpSession::serve(Request req) {
  const std::string target(req.target());
  if (target.size() > 8192) {
    req.keep_alive(false);
    return write(respond(req, http::status::uri_too_long, "a URL may have at most 8 KiB\n", "text/plain"));
  }
  const std::string path = target.substr(0, target.find('?'));
  if (!door_->allows_host(sv(req[http::field::host])))
    return write(respond(req, http::status::forbidden,
                         "Host '" + std::string(sv(req[http::field::host]).substr(0, 200)) + "' is not this server (it answers to " +
                             door_->names() + "); serve with --allow-origin http://NAME:PORT to be reached by another name\n",
                         "text/plain"));
  if (beast::websocket::is_upgrade(req)) {
    if (const auto origin = req.find(http::field::origin); origin != req.end() && !door_->allows_origin(sv(origin->value())))
      return write(respond(req, http::status::forbidden,
                           "a page from '" + std::string(sv(origin->value()).substr(0, 200)) + "' may not use this server; serve with "
                               "--allow-origin " + std::string(sv(origin->value()).substr(0, 200)) + " to let it\n",
                           "text/plain"));
    if (path != "/ws") return write(respond(req, http::status::not_found, "the WebSocket is at /ws\n", "text/plain"));
    if (host_.connections_open() > host_.options().limits.max_clients)  // this connection counted once
      return write(respond(req, http::status::service_unavailable,
                           error_text("too_many_clients", "the server has its maximum of connections (--max-clients)") + "\n",
                           "application/json"));
    stream_.expires_never();
    std::make_shared<WebSocketSession>(stream_.release_socket(), host_)->run(req);
    return;
  }
  if (req.method() != http::verb::get && req.method() != http::verb::head) {
    auto res = respond(req, http::status::method_not_allowed, "only GET and HEAD\n", "text/plain");
    res->set(http::field::allow, "GET, HEAD");
    return write(res);
  }
  if (path.rfind("/api/", 0) == 0) {
    if (host_.options().token && !loopback_ && !same_token(sv(req[http::field::authorization]), "Bearer " + *host_.options().token))
      return write(respond(req, http::status::unauthorized, "send the header Authorization: Bearer TOKEN\n", "text/plain"));
    if (path == "/api/world") return write(respond(req, http::status::ok, host_.world_text(), "application/json"));
    if (path == "/api/state") {
      auto self = shared_from_this();
      auto shared_req = std::make_shared<Request>(std::move(req));
      host_.request_state([self, shared_req](std::string body) {
        boost::asio::post(self->stream_.get_executor(), [self, shared_req, body = std::move(body)]() mutable {
          self->write(self->respond(*shared_req, http::status::ok, std::move(body), "application/json"));
        });
      });
      return;
    }
    return write(respond(req, http::status::not_found, "no such API: /api/world and /api/state\n", "text/plain"));
  }
  if (const auto file = static_file(web_root_, path)) return write_file(req, *file);
  if (path == "/" || path == "/index.html")
    return write(respond(req, http::status::ok, std::string(placeholder_page), "text/html; charset=utf-8"));
  write(respond(req, http::status::not_found, "not found\n", "text/plain"));
}

void HttpSession::write_file(const Request& req, const std::filesystem::path& file) {
  http::file_body::value_type body;
  beast::error_code ec;
  body.open(file.c_str(), beast::file_mode::scan, ec);
  if (ec) return write(respond(req, http::status::not_found, "not found\n", "text/plain"));
  const std::uint64_t size = body.size();
  auto res = std::make_shared<http::response<http::file_body>>(std::piecewise_construct, std::make_tuple(std::move(body)),
                                                                std::make_tuple(http::status::ok, req.version()));
  res->set(http::field::server, std::string(server_name));
  res->set(http::field::content_type, content_type(file));
  res->set(http::field::cache_control, "no-store");
  res->keep_alive(req.keep_alive());
  res->content_length(size);
  if (req.method() == http::verb::head) {  // the headers alone: an empty body of the file's length
    auto head = std::make_shared<http::response<http::empty_body>>(http::status::ok, req.version());
    head->base() = res->base();
    auto& out = *head;
    return http::async_write(stream_, out, [self = shared_from_this(), head](beast::error_code e, std::size_t) {
      self->written(e, head->keep_alive());
    });
  }
  auto& out = *res;
  http::async_write(stream_, out, [self = shared_from_this(), res](beast::error_code e, std::size_t) {
    self->written(e, res->keep_alive());
  });
}

void HttpSession::written(beast::error_code ec, bool keep_alive) {
  if (ec || !keep_alive) {
    beast::error_code ignored;
    stream_.socket().shutdown(boost::asio::ip::tcp::socket::shutdown_send, ignored);
    return;
  }
  read();
}

void HttpSession::write(std::shared_ptr<Response> res) {
  Response& out = *res;  // (taken before the lambda moves res: the order of the arguments is unspecified)
  http::async_write(stream_, out, [self = shared_from_this(), res = std::move(res)](beast::error_code ec, std::size_t) {
    if (ec || !res->keep_alive()) {
      beast::error_code ignored;
      self->stream_.socket().shutdown(boost::asio::ip::tcp::socket::shutdown_send, ignored);
      return;
    }
    self->read();
  });
}

}  // namespace turtlegas::server::detail
