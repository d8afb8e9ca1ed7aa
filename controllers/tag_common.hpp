// SPDX-License-Identifier: MIT
// Small helpers shared by the tag controllers (tag_chaser.cpp, tag_evader.cpp, tag_random.cpp).
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

}  // namespace turtlegas::controllers::detail
