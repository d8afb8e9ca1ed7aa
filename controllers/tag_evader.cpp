// SPDX-License-Identifier: MIT
// tag_evader: when not "it", keep moving along the walls by feel (a wall on the right) and flee
// from turtles that touch it; when "it", cross the arena in long straight legs looking for someone.
//   params: reach (units, default 40), curve (degrees, 20), back_off (units, 5), flee (units, 120),
//           leg (units, 500)
#include "tag_common.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void tag_evader(turtle::Turtle& t, const turtle::Params& p) {
  const double reach = p.get("reach", 40.0);
  const double curve = p.get("curve", 20.0);
  const double back_off = p.get("back_off", 5.0);
  const double flee = p.get("flee", 120.0);
  const double leg = p.get("leg", 500.0);
  for (;;) {
    if (t.it()) {
      const auto moved = t.forward(leg);
      if (moved.touched()) {
        t.back(back_off);
        detail::turn_away(t, moved.touch().bearing, 60.0);
      }
      continue;
    }
    const auto moved = t.forward(reach);
    if (!moved.touched()) {
      t.right(curve);  // nothing within reach: lean back towards the wall
    } else if (moved.touch().kind == "turtle") {
      if (t.it()) continue;  // that was a tag: play "it" from the next turn of the loop
      detail::turn_away(t, moved.touch().bearing, 20.0);
      t.forward(flee);
    } else {
      t.back(back_off);
      t.left(moved.touch().front() ? 90 : 30);
    }
  }
}

}  // namespace turtlegas::controllers
