// SPDX-License-Identifier: MIT
// Angles: radians inside the code, degrees at the world-file and controller-API boundary, in the
// Logo convention (heading 0 points to +y, headings grow clockwise, so a heading h in radians
// points along (sin h, cos h)). Every conversion outside the engine happens here, so that "where it
// converts" is one place. (The engine's own heading_vector, snapped near quarter turns, stays in
// the engine.)
#pragma once

#include <cmath>
#include <numbers>

#include "turtlegas/sim/vec2.hpp"

namespace turtlegas::sim {

/// Radians in one degree: degrees (world files, the controller API) to radians (inside) is a
/// product with it, and back a division by it.
inline constexpr double radians_per_degree = std::numbers::pi / 180.0;

/// Degrees to radians.
constexpr double to_radians(double degrees) { return degrees * radians_per_degree; }

/// Radians to degrees: one formula for what a program sees (Turtle::heading, a turn's done,
/// bearings) and what the state file and `expect` say, so the two never differ in the last bit.
/// A division by radians_per_degree rather than a product with 180/pi: it is the correctly
/// rounded degree value more often (89 % against 78 % of 200,000 random headings in [-4pi, 4pi],
/// checked against 60-digit pi), and it takes a degree value through to_radians and back
/// unchanged more often (93 % against 88 % of the integers -720..720 and of 3-decimal values).
constexpr double to_degrees(double radians) { return radians / radians_per_degree; }

/// An angle in degrees brought into [0, 360): touch bearings, sensor arcs, the API's heading, the
/// headings of world files, state files and draw builders. Within two turns either way one or two
/// exact steps of 360 give fmod's answer bit for bit (the differences are exact by Sterbenz's
/// lemma); fmod only beyond. A tiny negative angle plus 360 rounds to 360 itself: that is 0.
inline double wrap_degrees(double a) {
  if (a >= 0.0 && a < 360.0) return a;
  if (a >= 360.0 && a < 720.0) return a - 360.0;
  if (!(a < 0.0 && a > -360.0)) a = std::fmod(a, 360.0);
  if (a < 0.0) a += 360.0;
  if (a >= 360.0) a = 0.0;  // -1e-17 + 360
  return a;
}

/// The unit vector of a Logo heading in degrees: (sin h, cos h), exact (0 or ±1) at multiples of
/// 90 degrees, where the library's sin and cos of a radian value are not.
inline Vec2 heading_direction(double heading_degrees) {
  const double h = wrap_degrees(heading_degrees);
  // Quarter turns are exact: a square room drawn from integer corners closes exactly.
  if (h == 0.0) return {0.0, 1.0};
  if (h == 90.0) return {1.0, 0.0};
  if (h == 180.0) return {0.0, -1.0};
  if (h == 270.0) return {-1.0, 0.0};
  const double r = h * radians_per_degree;
  return {std::sin(r), std::cos(r)};
}

/// The unit vector of a Logo heading in radians, (sin h, cos h), not snapped (a picture's heading
/// tick).
inline Vec2 heading_unit(double heading) { return {std::sin(heading), std::cos(heading)}; }

/// The Logo heading of a direction, in radians in (-π, π]: atan2(x, y) (0 along +y, clockwise).
inline double heading_of(Vec2 d) { return std::atan2(d.x, d.y); }

}  // namespace turtlegas::sim
