// SPDX-License-Identifier: MIT
// tag_evader: when not "it", keep moving along the walls by feel (a wall on the right) and flee
// from turtles that touch it; when "it", cross the arena in long straight legs looking for someone.
//   params: declared in tag_evader_info() below (`turtlegas controllers` lists them)
#include "tag_common.hpp"
#include <limits>

#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void tag_evader(turtle::Turtle& t, const turtle::Params& p) {
  const double reach = p.get<double>("reach");
  const double curve = p.get<double>("curve");
  const double back_off = p.get<double>("back_off");
  const double flee = p.get<double>("flee");
  const double leg = p.get<double>("leg");
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

turtle::ControllerInfo tag_evader_info() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  turtle::ControllerInfo info;
  info.summary = "tag: when not it, follow walls and flee touches";
  info.params = {turtle::number_param("reach", 40.0, 0, inf, "how far to feel ahead along the wall, units"),
                 turtle::number_param("curve", 20.0, -360, 360, "the turn back towards the wall, degrees"),
                 turtle::number_param("back_off", 5.0, 0, inf, "how far to back off after a touch, units"),
                 turtle::number_param("flee", 120.0, 0, inf, "how far to flee a turtle's touch, units"),
                 turtle::number_param("leg", 500.0, 0, inf, "the straight legs when it, units")};
  info.restartable = true;  // it reads its Turtle and Params only
  return info;
}

}  // namespace turtlegas::controllers
