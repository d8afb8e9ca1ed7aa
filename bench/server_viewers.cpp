// SPDX-License-Identifier: MIT
// The C++ viewers of bench/server_bench.py (issue 12, section 7): N WebSocket connections to a
// running `turtlegas serve`, each subscribed to binary (or JSON) frames at a rate, counting the
// frames and bytes they receive for a while, without decoding them (so that the reader is not
// what is measured; the Python readers fell behind at 50 viewers of 10^4 balls). Prints one JSON
// line. Not a test.
//
//   server_viewers PORT VIEWERS RATE SECONDS [binary|json]
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: server_viewers PORT VIEWERS RATE SECONDS [binary|json]\n");
    return 2;
  }
  const auto port = static_cast<unsigned short>(std::atoi(argv[1]));
  const int viewers = std::atoi(argv[2]), rate = std::atoi(argv[3]);
  const double seconds = std::atof(argv[4]);
  const std::string format = argc > 5 ? argv[5] : "binary";
  std::atomic<bool> counting{false}, stop{false};
  std::vector<std::uint64_t> frames(static_cast<std::size_t>(viewers)), bytes(static_cast<std::size_t>(viewers));
  std::vector<std::thread> threads;
  threads.reserve(static_cast<std::size_t>(viewers));
  std::atomic<int> ready{0};
  for (int k = 0; k < viewers; ++k)
    threads.emplace_back([&, k] {
      asio::io_context io;
      websocket::stream<tcp::socket> ws(io);
      beast::get_lowest_layer(ws).connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
      ws.read_message_max(256 << 20);
      ws.handshake("127.0.0.1:" + std::to_string(port), "/ws");
      ws.text(true);
      ws.write(asio::buffer(std::string(R"({"type": "hello", "protocol": "turtlegas/1"})")));
      ws.write(asio::buffer(R"({"type": "subscribe", "rate": )" + std::to_string(rate) + R"(, "format": ")" + format + "\"}"));
      ++ready;
      beast::flat_buffer buf;
      beast::error_code ec;
      while (!stop) {
        buf.clear();
        ws.read(buf, ec);
        if (ec) break;
        const bool frame = format == "binary" ? ws.got_binary() : true;
        if (counting && frame) {
          ++frames[static_cast<std::size_t>(k)];
          bytes[static_cast<std::size_t>(k)] += buf.size();
        }
      }
      beast::get_lowest_layer(ws).close(ec);
    });
  while (ready < viewers) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::seconds(1));  // the snapshots go by
  counting = true;
  const auto t0 = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  counting = false;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  stop = true;
  std::uint64_t f = 0, b = 0, fmin = ~0ull;
  for (int k = 0; k < viewers; ++k) {
    f += frames[static_cast<std::size_t>(k)];
    b += bytes[static_cast<std::size_t>(k)];
    fmin = std::min(fmin, frames[static_cast<std::size_t>(k)]);
  }
  std::printf("{\"viewers\": %d, \"frames_per_s_per_viewer\": %.3f, \"slowest_viewer_frames_per_s\": %.3f, "
              "\"MB_per_s\": %.3f, \"MB_per_s_per_viewer\": %.3f}\n",
              viewers, static_cast<double>(f) / wall / viewers, static_cast<double>(fmin) / wall,
              static_cast<double>(b) / wall / 1e6, static_cast<double>(b) / wall / 1e6 / viewers);
  std::fflush(stdout);
  std::_Exit(0);  // the readers block in read(); the server closes them when it stops
}
