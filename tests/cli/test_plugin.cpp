// SPDX-License-Identifier: MIT
// A controller plugin for the CLI tests: programs that misbehave in the ways a run must survive
// or report.
//   spinner    drives a little, then loops without ever issuing another command (a busy loop)
//   allocator  drives a little, then allocates and frees in a loop without a command (a busy loop
//              that is inside malloc much of the time)
//   poller     drives a little, then loops reading t.time() without a command (a busy loop that
//              calls the Turtle API)
//   swallower  catches every exception around its commands, the one that ends it at teardown too
//   big_frame  calls a function with a 200 KiB local array (a frame far larger than the guard page)
//   bad_amount forward(NaN) or right(inf), as params.call says
//   crasher    after params.after seconds: a null dereference, abort() or exit(7) (params.how)
//   segfaulter, aborter, exiter: drive a little, then crash in that way (`turtlegas test` fails that world)
//   (TURTLEGAS_TEST_PLUGIN_THROW set: the registration throws; TURTLEGAS_TEST_PLUGIN_CLASH=NAME: it
//   also registers NAME, for the loader's tests)
//   chatty     logs a line, then drives back and forth (a passing world with a log)
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace {

using turtlegas::turtle::Params;
using turtlegas::turtle::Turtle;

[[gnu::noinline]] double big_frame(double x) {
  char frame[200 * 1024];
  frame[0] = static_cast<char>(x);  // the lowest address, 200 KiB below the caller's frame
  frame[sizeof frame - 1] = static_cast<char>(x);
  // The array's address escapes, so the whole frame must exist: clang 14 kept only the two bytes
  // of a `volatile char frame[...]` that are touched (an 8-byte frame), and the test passed by
  // never overflowing anything.
  asm volatile("" : : "r"(frame) : "memory");
  return frame[0] + frame[sizeof frame - 1];
}

}  // namespace

namespace {

int* volatile g_nowhere = nullptr;

}  // namespace

extern "C" void turtlegas_register(turtlegas::turtle::Registry& registry) {
  using turtlegas::turtle::Params;
  using turtlegas::turtle::Turtle;
  // For the loader's tests: a registration that throws, or one that takes a name already taken.
  if (std::getenv("TURTLEGAS_TEST_PLUGIN_THROW") != nullptr) throw std::runtime_error("asked to throw");
  if (const char* name = std::getenv("TURTLEGAS_TEST_PLUGIN_CLASH"))
    registry.add(name, [](Turtle& t, const Params&) { t.forward(1); }, "a clash, for tests");
  registry.add(
      "spinner",
      [](Turtle& t, const Params&) {
        t.forward(10);
        volatile std::uint64_t n = 0;
        for (;;) n = n + 1;
      },
      "a busy loop, for tests");
  registry.add(
      "allocator",
      [](Turtle& t, const Params&) {
        t.forward(10);
        std::vector<std::unique_ptr<std::string>> held(64);
        for (std::uint64_t n = 0;; ++n) held[n % held.size()] = std::make_unique<std::string>(100 + n % 300, 'x');
      },
      "a busy loop that allocates, for tests");
  registry.add(
      "poller",
      [](Turtle& t, const Params&) {
        t.forward(10);
        volatile double sum = 0.0;
        for (;;) sum = sum + t.time();
      },
      "a busy loop that calls the Turtle API, for tests");
  registry.add(
      "swallower",
      [](Turtle& t, const Params&) {
        for (;;) {
          try {
            t.forward(1000);
            t.right(90);
          } catch (...) {  // NOLINT(bugprone-empty-catch): the misbehaviour under test
          }
        }
      },
      "catches everything, also the end of the run, for tests");
  registry.add(
      "big_frame",
      [](Turtle& t, const Params&) {
        t.forward(10);
        t.forward(big_frame(1.0));
      },
      "a 200 KiB stack frame, for tests");
  registry.add(
      "bad_amount",
      [](Turtle& t, const Params& p) {
        t.forward(5);
        const std::string call = p.get<std::string>("call", "forward");
        if (call == "forward") t.forward(std::nan(""));
        if (call == "right") t.right(std::numeric_limits<double>::infinity());
        t.forward(5);
      },
      "forward(NaN) or right(inf), for tests");
  registry.add(
      "crasher",
      [](Turtle& t, const Params& p) {
        t.wait(p.get("after", 0.5));
        const std::string how = p.get<std::string>("how", "null");
        if (how == "null") {
          volatile int* volatile nowhere = nullptr;
          *nowhere = 1;  // NOLINT(clang-analyzer-core.NullDereference): the crash is the point
        }
        if (how == "abort") std::abort();
        if (how == "exit") std::exit(7);
        t.forward(10);
      },
      "crashes the process after a while, for tests");
  registry.add(
      "segfaulter",
      [](Turtle& t, const Params&) {
        t.forward(10);
        *g_nowhere = 1;
      },
      "a crash, for tests");
  registry.add(
      "aborter",
      [](Turtle& t, const Params&) {
        t.forward(10);
        std::abort();
      },
      "std::abort(), for tests");
  registry.add(
      "exiter",
      [](Turtle& t, const Params&) {
        t.forward(10);
        std::exit(7);
      },
      "std::exit(7), for tests");
  registry.add(
      "chatty",
      [](Turtle& t, const Params&) {
        t.log("hello from chatty & <friends>");
        for (;;) {
          t.forward(10);
          t.back(10);
        }
      },
      "a log line, then back and forth, for tests");
}
