// SPDX-License-Identifier: MIT
// A controller plugin for the CLI tests: "spinner" drives a little, then loops without ever issuing
// another command (a busy loop the run must stop).
#include <cstdint>

#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/registry.hpp"

extern "C" void turtlegas_register(turtlegas::turtle::Registry& registry) {
  registry.add(
      "spinner",
      [](turtlegas::turtle::Turtle& t, const turtlegas::turtle::Params&) {
        t.forward(10);
        volatile std::uint64_t n = 0;
        for (;;) n = n + 1;
      },
      "a busy loop, for tests");
}
