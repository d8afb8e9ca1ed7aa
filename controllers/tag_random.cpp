// SPDX-License-Identifier: MIT
// tag_random: the baseline. Ignores its role: legs of random length in random directions,
// backing off from whatever it touches.
//   params: leg (units, the longest leg, default 300), back_off (units, 5)
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void tag_random(turtle::Turtle& t, const turtle::Params& p) {
  const double leg = p.get("leg", 300.0);
  const double back_off = p.get("back_off", 5.0);
  for (;;) {
    if (t.forward(leg * t.uniform()).touched()) t.back(back_off);
    t.right((2.0 * t.uniform() - 1.0) * 180.0);
  }
}

}  // namespace turtlegas::controllers
