// SPDX-License-Identifier: MIT
// Small helpers shared by the tag controllers (tag_chaser.cpp, tag_evader.cpp, tag_random.cpp,
// tag_camera.cpp).
#pragma once

#include <cmath>

#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers::detail {

/// An angle in degrees folded into [-180, 180): the shortest turn to it, for right().
inline double shortest_turn(double degrees) {
  double a = std::fmod(degrees + 180.0, 360.0);
  if (a < 0.0) a += 360.0;
  return a - 180.0;
}

/// Turns away from a touch at `bearing` (degrees clockwise from the heading), give or take
/// `spread` degrees at random either way.
inline void turn_away(turtle::Turtle& t, double bearing, double spread) {
  t.right(shortest_turn(bearing + 180.0 + (2.0 * t.uniform() - 1.0) * spread));
}

/// The end of a sweeping leg of the one who is "it": after running into a wall or a ball, back
/// off and turn away from it (after a turtle, only turn away); after a free leg, turn at random
/// up to 90 degrees either way.
inline void after_sweep(turtle::Turtle& t, const turtle::Result& moved, double back_off) {
  if (moved.touched()) {
    if (moved.touch().kind != "turtle") t.back(back_off);
    turn_away(t, moved.touch().bearing, 70.0);
  } else {
    t.right((2.0 * t.uniform() - 1.0) * 90.0);
  }
}

/// Standing still while not "it": a turtle that touched it is fled, `flee` units straight away.
inline void flee_touch(turtle::Turtle& t, const turtle::Result& still, double flee) {
  if (still.touched() && still.touch().kind == "turtle" && !t.it()) {
    turn_away(t, still.touch().bearing, 30.0);
    t.forward(flee);
  }
}

}  // namespace turtlegas::controllers::detail
