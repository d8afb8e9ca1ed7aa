// SPDX-License-Identifier: MIT
// wall_follower: keep a wall on one side (params.hand "right" (default) or "left").
//
// Feel along the wall in short hops: after each hop, turn towards the wall and probe; a touch
// means the wall is still there, so turn back along it; no touch means a corner went away, so
// follow it round. Touching something ahead means an inside corner: turn away from the wall.
//   params: hand, hop (default 20), probe (default 12), back_off (default 3)
#include <string>

#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void wall_follower(turtle::Turtle& t, const turtle::Params& p) {
  const bool right_hand = p.get<std::string>("hand", "right") != "left";
  const double hop = p.get("hop", 20.0);
  const double probe = p.get("probe", 12.0);
  const double back_off = p.get("back_off", 3.0);
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

}  // namespace turtlegas::controllers
