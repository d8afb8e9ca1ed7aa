// SPDX-License-Identifier: MIT
// spiral: the Logo square spiral. Each side is `grow` longer than the last; a touch ends it.
//   params: start (default 5), grow (default 5), angle (degrees, default 90), sides (default 200)
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void spiral(turtle::Turtle& t, const turtle::Params& p) {
  double side = p.get("start", 5.0);
  const double grow = p.get("grow", 5.0);
  const double angle = p.get("angle", 90.0);
  const int sides = p.get("sides", 200);
  for (int k = 0; k < sides; ++k) {
    if (t.forward(side).touched()) return;  // ran into something: done
    t.right(angle);
    side += grow;
  }
}

}  // namespace turtlegas::controllers
