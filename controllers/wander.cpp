// SPDX-License-Identifier: MIT
// wander: go until something is touched, back off, turn a random angle, repeat.
//   params: step (how far to try, default 1000), back_off (default 5), max_turn (degrees, 180)
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void wander(turtle::Turtle& t, const turtle::Params& p) {
  const double step = p.get("step", 1000.0);
  const double back_off = p.get("back_off", 5.0);
  const double max_turn = p.get("max_turn", 180.0);
  for (;;) {
    const auto moved = t.forward(step);
    if (moved.touched()) t.back(back_off);
    // A random turn either way; uniform() is the turtle's own seeded stream, so runs repeat.
    t.right((2.0 * t.uniform() - 1.0) * max_turn);
  }
}

}  // namespace turtlegas::controllers
