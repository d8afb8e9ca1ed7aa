// SPDX-License-Identifier: MIT
// The floor of a lockstep round trip, from C++ (client.hpp): a remote turtle's
// commands whose results are immediate (pen: the same control boundary) or one control step away
// (left 1, forward 1), sent one after the other over TCP lines or WebSocket to a running
// `turtlegas serve` (world with a remote turtle "t1", at --speed max). Beside the Python figures of
// bench/server_bench.py (docs/performance.md) it says how much of a round trip is the client's. Prints one JSON line per
// command kind. Not a test.
//
//   server_latency LINE_PORT HTTP_PORT COUNT
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "client.hpp"

using namespace turtlegas::test;

namespace {

int run(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: server_latency LINE_PORT HTTP_PORT COUNT\n");
    return 2;
  }
  const auto line_port = static_cast<unsigned short>(std::atoi(argv[1]));
  const auto http_port = static_cast<unsigned short>(std::atoi(argv[2]));
  const int n = std::atoi(argv[3]);
  for (const char* transport : {"lines", "ws"}) {
    auto c = std::string(transport) == "lines" ? Client::lines(line_port) : Client::ws(http_port);
    c->request({{"type", "hello"}, {"protocol", "turtlegas/1"}});
    c->request({{"type", "claim"}, {"turtle", "t1"}});
    c->request({{"type", "resume"}});
    const std::vector<std::pair<const char*, json>> kinds = {
        {"pen", {{"type", "pen"}, {"turtle", "t1"}, {"down", true}}},
        {"left 1", {{"type", "left"}, {"turtle", "t1"}, {"amount", 1}}},
        {"forward 1, back 1", {{"type", "forward"}, {"turtle", "t1"}, {"amount", 1}}},
    };
    for (const auto& [name, m] : kinds) {
      std::vector<double> us;
      bool back = false;
      for (int k = 0; k < n + 50; ++k) {
        json msg = m;
        if (std::string(name).rfind("forward", 0) == 0) msg["type"] = (back = !back) ? "forward" : "back";
        const auto a = std::chrono::steady_clock::now();
        c->request(msg);
        const double d = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - a).count();
        if (k >= 50) us.push_back(d);
      }
      double sum = 0;
      for (double d : us) sum += d;
      std::sort(us.begin(), us.end());
      std::printf("{\"client\": \"C++\", \"transport\": \"%s\", \"command\": \"%s\", \"median_us\": %.1f, \"p90_us\": %.1f, "
                  "\"commands_per_s\": %.0f}\n",
                  transport, name, us[us.size() / 2], us[us.size() * 9 / 10], 1e6 * static_cast<double>(us.size()) / sum);
      std::fflush(stdout);
    }
    c->request({{"type", "release"}, {"turtle", "t1"}});
  }
  return 0;
}

}  // namespace

// A server that cannot be reached, or that answers with an error, ends the run with its message.
int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "server_latency: %s\n", e.what());
    return 1;
  }
}
