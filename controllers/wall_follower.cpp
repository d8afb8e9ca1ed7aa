// SPDX-License-Identifier: MIT
// wall_follower: keep a wall on one side (params.hand "right" (default) or "left").
//
// Feel along the wall in short hops: after each hop, turn towards the wall and probe; a touch
// means the wall is still there, so turn back along it; no touch means a corner went away, so
// follow it round. Touching something ahead means an inside corner: turn away from the wall.
//   params: declared in wall_follower_info() below (`turtlegas controllers` lists them)
#include <string>

#include <limits>

#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void wall_follower(turtle::Turtle& t, const turtle::Params& p) {
  const bool right_hand = p.get<std::string>("hand") != "left";
  const double hop = p.get<double>("hop");
  const double probe = p.get<double>("probe");
  const double back_off = p.get<double>("back_off");
  auto towards_wall = [&](double deg) { return right_hand ? t.right(deg) : t.left(deg); };
  auto away_from_wall = [&](double deg) { return right_hand ? t.left(deg) : t.right(deg); };

  // Find a wall first: straight ahead until something is touched, then put it on our hand's side.
  while (!t.forward(1000).touched()) t.right(90 * t.uniform());
  t.back(back_off);
  away_from_wall(90);
  for (;;) {
    if (t.forward(hop).touched()) {
      // Inside corner (or an obstacle): turn away from the wall.
      t.back(back_off);
      away_from_wall(90);
      continue;
    }
    // Probe sideways for the wall.
    towards_wall(90);
    if (t.forward(probe).touched()) {
      t.back(back_off);
      away_from_wall(90);
    }
    // No touch: the wall turned away (an outside corner); keep the new heading and go on.
  }
}

turtle::ControllerInfo wall_follower_info() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  turtle::ControllerInfo info;
  info.summary = "keep a wall on one side";
  info.params = {turtle::string_param("hand", "right", {"right", "left"}, "which side the wall is kept on"),
                 turtle::number_param("hop", 20.0, 0, inf, "how far to drive along the wall between probes, units"),
                 turtle::number_param("probe", 12.0, 0, inf, "how far to reach sideways for the wall, units"),
                 turtle::number_param("back_off", 3.0, 0, inf, "how far to back off after a touch, units")};
  info.restartable = true;  // it reads its Turtle and Params only
  return info;
}

}  // namespace turtlegas::controllers
