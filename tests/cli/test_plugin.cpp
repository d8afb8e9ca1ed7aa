// SPDX-License-Identifier: MIT
// A controller plugin for the CLI tests: programs that misbehave.
//   spinner     drives a little, then loops without ever issuing another command (a busy loop the
//               run must stop, or a hang `turtlegas test --timeout` must kill)
//   segfaulter  drives a little, then writes through a null pointer (the process crashes)
//   aborter     drives a little, then calls std::abort()
//   exiter      drives a little, then calls std::exit(7)
//   chatty      logs a line, then drives back and forth (a passing world with a log)
#include <cstdint>
#include <cstdlib>

#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/registry.hpp"

namespace {

int* volatile nowhere = nullptr;

}  // namespace

extern "C" void turtlegas_register(turtlegas::turtle::Registry& registry) {
  using turtlegas::turtle::Params;
  using turtlegas::turtle::Turtle;
  registry.add(
      "spinner",
      [](Turtle& t, const Params&) {
        t.forward(10);
        volatile std::uint64_t n = 0;
        for (;;) n = n + 1;
      },
      "a busy loop, for tests");
  registry.add(
      "segfaulter",
      [](Turtle& t, const Params&) {
        t.forward(10);
        *nowhere = 1;
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
