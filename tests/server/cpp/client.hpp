// SPDX-License-Identifier: MIT
// A small blocking client of the world server (docs/protocol.md) in C++, over WebSocket (Boost.Beast)
// or TCP lines (Boost.Asio), for tests and benchmarks: it sends JSON messages, waits for the reply
// to a request by its id and keeps everything else (frames, touches, status) in arrival order. And
// a way to start `turtlegas serve --port 0` and read the ports it prints.
#pragma once

#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <deque>
#include <memory>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

namespace turtlegas::test {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using nlohmann::json;

/// `turtlegas serve WORLD --port 0 ARGS...` as a child process; the destructor stops it (SIGINT,
/// then waits).
class ServeProcess {
 public:
  ServeProcess(const std::string& bin, const std::string& world, const std::vector<std::string>& args) {
    int out[2];
    if (pipe(out) != 0) throw std::runtime_error("pipe");
    pid_ = fork();
    if (pid_ < 0) throw std::runtime_error("fork");
    if (pid_ == 0) {
      dup2(out[1], 1);
      close(out[0]);
      close(out[1]);
      std::vector<std::string> a = {bin, "serve", world, "--port", "0"};
      a.insert(a.end(), args.begin(), args.end());
      std::vector<char*> argv;
      argv.reserve(a.size() + 1);
      for (auto& s : a) argv.push_back(s.data());
      argv.push_back(nullptr);
      execv(bin.c_str(), argv.data());
      _exit(127);
    }
    close(out[1]);
    FILE* f = fdopen(out[0], "r");
    char line[512];
    const std::regex http(R"(listening on http://127\.0\.0\.1:(\d+)/)"), lines(R"(lines on tcp://127\.0\.0\.1:(\d+))");
    std::smatch m;
    while ((http_port == 0 || line_port == 0) && std::fgets(line, sizeof line, f)) {
      const std::string s(line);
      if (std::regex_search(s, m, http)) http_port = static_cast<unsigned short>(std::stoi(m[1]));
      if (std::regex_search(s, m, lines)) line_port = static_cast<unsigned short>(std::stoi(m[1]));
    }
    out_ = f;  // kept open: the server keeps printing nothing much, but must not get SIGPIPE
    if (http_port == 0 || line_port == 0) throw std::runtime_error("the server did not print its URLs");
  }
  ~ServeProcess() { stop(); }
  ServeProcess(const ServeProcess&) = delete;
  ServeProcess& operator=(const ServeProcess&) = delete;
  /// SIGINT and the exit status (the server stops at a boundary and says bye).
  int stop() {
    if (pid_ <= 0) return status_;
    kill(pid_, SIGINT);
    int st = 0;
    waitpid(pid_, &st, 0);
    pid_ = 0;
    if (out_) std::fclose(out_);
    out_ = nullptr;
    status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    return status_;
  }
  unsigned short http_port = 0, line_port = 0;

 private:
  pid_t pid_ = 0;
  FILE* out_ = nullptr;
  int status_ = -1;
};

/// The error reply to a request.
struct ServerError : std::runtime_error {
  explicit ServerError(json r) : std::runtime_error(r.dump()), reply(std::move(r)) {}
  json reply;
};

/// One connection. Not thread-safe: one thread sends and receives.
class Client {
 public:
  /// TCP lines to `port`.
  static std::unique_ptr<Client> lines(unsigned short port) {
    auto c = std::unique_ptr<Client>(new Client());
    c->sock_.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    c->sock_.set_option(tcp::no_delay(true));
    return c;
  }
  /// WebSocket to ws://127.0.0.1:port/ws.
  static std::unique_ptr<Client> ws(unsigned short port) {
    auto c = std::unique_ptr<Client>(new Client());
    c->ws_ = std::make_unique<websocket::stream<tcp::socket>>(c->io_);
    beast::get_lowest_layer(*c->ws_).connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    beast::get_lowest_layer(*c->ws_).set_option(tcp::no_delay(true));
    c->ws_->read_message_max(64 << 20);
    c->ws_->handshake("127.0.0.1:" + std::to_string(port), "/ws");
    return c;
  }

  void send(const json& m) { send_text(m.dump()); }
  void send_text(const std::string& text) {
    if (ws_) {
      ws_->text(true);
      ws_->write(asio::buffer(text));
    } else {
      const std::string line = text + "\n";
      asio::write(sock_, asio::buffer(line));
    }
  }
  /// The next message as text; `binary` says whether it was a binary WebSocket frame.
  std::string receive_text(bool* binary = nullptr) {
    if (ws_) {
      buffer_.clear();
      ws_->read(buffer_);
      if (binary) *binary = ws_->got_binary();
      return beast::buffers_to_string(buffer_.data());
    }
    if (binary) *binary = false;
    const std::size_t n = asio::read_until(sock_, lines_, '\n');
    std::string line(asio::buffers_begin(lines_.data()), asio::buffers_begin(lines_.data()) + static_cast<std::ptrdiff_t>(n) - 1);
    lines_.consume(n);
    return line;
  }
  /// The next JSON message: one kept from before, or one read now (binary frames are skipped).
  json next() {
    if (!kept_.empty()) {
      json m = std::move(kept_.front());
      kept_.pop_front();
      return m;
    }
    for (;;) {
      bool binary = false;
      std::string text = receive_text(&binary);
      if (!binary) return json::parse(text);
    }
  }
  /// Sends m with a fresh id and returns the reply with that id (throws ServerError for an error
  /// reply); other messages meanwhile are kept for next().
  json request(json m) {
    const long id = ++last_id_;
    m["id"] = id;
    send(m);
    for (;;) {
      bool binary = false;
      std::string text = receive_text(&binary);
      if (binary) continue;
      json r = json::parse(text);
      if (r.contains("id") && r["id"] == id) {
        if (r.value("type", "") == "error") throw ServerError(r);
        return r;
      }
      kept_.push_back(std::move(r));
    }
  }
  const std::deque<json>& kept() const { return kept_; }

 private:
  Client() : sock_(io_) {}
  asio::io_context io_;
  tcp::socket sock_;
  std::unique_ptr<websocket::stream<tcp::socket>> ws_;
  beast::flat_buffer buffer_;
  asio::streambuf lines_;
  std::deque<json> kept_;
  long last_id_ = 0;
};

}  // namespace turtlegas::test
