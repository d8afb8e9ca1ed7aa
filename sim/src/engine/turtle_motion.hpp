// SPDX-License-Identifier: MIT
// Turtles: a command in progress, and the Logo heading's unit vector.
#pragma once

#include <cmath>

#include "turtlegas/sim/vec2.hpp"
#include "turtlegas/sim/world.hpp"

namespace turtlegas::sim::detail {
namespace {

/// A turtle's command in progress, in the engine's internal time.
struct TurtleRun {
  TurtleCommand::Kind kind = TurtleCommand::Kind::stop;
  bool coasting = false;  ///< bouncing off after a contact, until the next control step
  bool touched = false;
  double amount = 0.0;
  double t_start = 0.0;  ///< (its end is in the turtle's Record: Engine::end_)
  double heading0 = 0.0;  ///< heading at t_start
  double omega = 0.0;     ///< signed turn rate while turning
  double speed = 0.0;
  double turn_rate = 0.0;
  double bounce = -1.0;
};

/// The unit vector of a Logo heading (radians; 0 is +y, clockwise). Headings within 1e-9 degrees
/// of a multiple of 90 give the exact axis: cos(pi/2) is 6e-17, not 0, and a turtle that has
/// turned to drive along the wall it touches would otherwise "approach" it at 1e-15 units/s and
/// stop at once.
Vec2 heading_vector(double heading) {
  const double deg = heading * (180.0 / 3.141592653589793);
  const double quarter = std::round(deg / 90.0);
  if (std::abs(deg - 90.0 * quarter) < 1e-9) {
    switch (((static_cast<long long>(quarter) % 4) + 4) % 4) {
      case 0: return {0.0, 1.0};
      case 1: return {1.0, 0.0};
      case 2: return {0.0, -1.0};
      default: return {-1.0, 0.0};
    }
  }
  return {std::sin(heading), std::cos(heading)};
}

}  // namespace
}  // namespace turtlegas::sim::detail
