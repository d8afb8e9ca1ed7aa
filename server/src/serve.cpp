// SPDX-License-Identifier: MIT
#include "turtlegas/server/serve.hpp"

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <thread>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/address.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>
#include <spdlog/spdlog.h>

#include "http_session.hpp"
#include "line_session.hpp"
#include "listener.hpp"
#include "turtlegas/server/protocol.hpp"

namespace turtlegas::server {

namespace asio = boost::asio;

std::filesystem::path default_web_root() {
  // The installed page beside the program (BINDIR/../share/turtlegas/web), else the source tree's.
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    std::filesystem::path installed = (exe.parent_path() / TURTLEGAS_WEB_FROM_BIN).lexically_normal();
    if (std::filesystem::is_regular_file(installed / "index.html", ec)) return installed;
  }
  return TURTLEGAS_DEFAULT_WEB_ROOT;
}

int serve(ServeOptions options, const turtle::Registry& registry, world::Scene scene) {
  boost::system::error_code ec;
  const asio::ip::address address = asio::ip::make_address(options.bind, ec);
  if (ec) throw std::invalid_argument("--bind: '" + options.bind + "' is not an IP address (e.g. 127.0.0.1 or 0.0.0.0)");
  if (!address.is_loopback() && !options.host.token)
    throw std::invalid_argument("--bind " + options.bind +
                                " is not a loopback address: give a --token so that only clients that know it can control the world");
  const std::filesystem::path web_root = options.web_root.empty() ? default_web_root() : options.web_root;

  asio::io_context ioc(1);  // before the host: the host's sessions go before their io_context
  const std::string file = options.host.world_file;
  std::unique_ptr<WorldHost> owned;
  try {
    owned = std::make_unique<WorldHost>(options.host, registry, std::move(scene));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(file + ": " + e.what());
  }
  WorldHost& host = *owned;
  std::shared_ptr<detail::Listener> http, lines;
  auto listen = [&](unsigned short port, detail::Listener::OnAccept on_accept, const char* what) {
    try {
      return std::make_shared<detail::Listener>(ioc, asio::ip::tcp::endpoint(address, port), std::move(on_accept));
    } catch (const boost::system::system_error& e) {
      throw std::runtime_error(std::string("cannot listen for ") + what + " on " + options.bind + ":" +
                               std::to_string(port) + ": " + e.code().message() + " (choose another port, or 0 for any)");
    }
  };
  // Filled in once the port is known (port 0), before the first accept.
  auto door = std::make_shared<detail::Door>();
  // Over --max-clients: told once, then closed (docs/protocol.md, "Limits").
  auto refuse = [](asio::ip::tcp::socket&& s, std::string text) {
    auto sock = std::make_shared<asio::ip::tcp::socket>(std::move(s));
    auto shared = std::make_shared<std::string>(std::move(text));
    asio::async_write(*sock, asio::buffer(*shared), [sock, shared](boost::system::error_code, std::size_t) {
      boost::system::error_code ignored;
      sock->shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
    });
  };
  const std::string too_many = error_text("too_many_clients", "the server has its maximum of connections (--max-clients)");
  http = listen(options.port, [&host, web_root, door, refuse, too_many](asio::ip::tcp::socket&& s) {
    if (host.connections_open() >= host.options().limits.max_clients)
      return refuse(std::move(s), "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/json\r\nContent-Length: " +
                                      std::to_string(too_many.size() + 1) + "\r\nConnection: close\r\n\r\n" + too_many + "\n");
    std::make_shared<detail::HttpSession>(std::move(s), host, web_root, door)->run();
  }, "HTTP");
  *door = detail::make_door(options.bind, http->port(), options.allow_origins);
  const unsigned short line_port = options.line_port ? *options.line_port : options.port == 0 ? 0 : static_cast<unsigned short>(options.port + 1);
  lines = listen(line_port, [&host, refuse, too_many](asio::ip::tcp::socket&& s) {
    if (host.connections_open() >= host.options().limits.max_clients) return refuse(std::move(s), too_many + "\n");
    std::make_shared<detail::LineSession>(std::move(s), host)->run();
  }, "TCP lines");
  http->run();
  lines->run();
  const std::string shown = address.is_v6() ? "[" + options.bind + "]" : options.bind;
  std::printf("listening on http://%s:%u/\nlines on tcp://%s:%u\n", shown.c_str(), http->port(), shown.c_str(), lines->port());
  std::fflush(stdout);

  asio::signal_set signals(ioc, SIGINT, SIGTERM);
  // SIGINT and SIGTERM both stop with the reason "signal" (docs/protocol.md).
  signals.async_wait([&host](boost::system::error_code e, int /*sig*/) {
    if (!e) host.request_stop("signal");
  });
  // When the world has stopped: no new connections, the clients' last messages written, then out.
  asio::steady_timer grace(ioc);
  host.on_finished = [&] {
    asio::post(ioc, [&] {
      http->stop();
      lines->stop();
      signals.cancel();
      grace.expires_after(std::chrono::milliseconds(500));
      grace.async_wait([&](boost::system::error_code) { ioc.stop(); });
    });
  };
  // The simulation on the calling (main) thread, as `turtlegas run` has it: the fibers' signal
  // handling (an alternate signal stack, the busy-loop watchdog; turtle_runtime/src/fiber.cpp)
  // then lives on a thread that never exits before the process does. I/O on a thread of its own.
  std::thread io([&] { ioc.run(); });
  int code = 0;
  try {
    code = host.run();
  } catch (...) {
    asio::post(ioc, [&] { ioc.stop(); });
    io.join();
    throw;
  }
  io.join();
  return code;
}

}  // namespace turtlegas::server
