// SPDX-License-Identifier: MIT
// square: drive a square, `laps` times (0: forever). A touch makes it turn the corner early.
//   params: side (default 100), laps (default 0), left (bool: counter-clockwise, default false)
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void square(turtle::Turtle& t, const turtle::Params& p) {
  const double side = p.get("side", 100.0);
  const int laps = p.get("laps", 0);
  const bool left = p.get("left", false);
  for (int lap = 0; laps == 0 || lap < laps; ++lap)
    for (int k = 0; k < 4; ++k) {
      t.forward(side);
      if (left) t.left(90);
      else t.right(90);
    }
}

}  // namespace turtlegas::controllers
