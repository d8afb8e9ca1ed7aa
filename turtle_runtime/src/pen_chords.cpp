// SPDX-License-Identifier: MIT
#include "pen_chords.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "turtlegas/sim/angles.hpp"

namespace turtlegas::turtle::detail {

double drawn_turn(double turned) {
  constexpr double lap = 2.0 * std::numbers::pi;
  const double a = std::abs(turned);
  return std::copysign(a > lap ? lap + std::fmod(a, lap) : a, turned);
}

std::vector<sim::Vec2> arc_chords(sim::Vec2 start, double heading, double speed, double rate, double turned,
                                  sim::Vec2 end, double radius) {
  if (rate == 0.0 || speed == 0.0 || !std::isfinite(turned)) return {end};
  // Laps past the first draw the same circle again: one lap, then what is left of the turn.
  const double drawn = drawn_turn(turned);
  // The circle's radius is |speed / rate|; a chord spanning theta departs from it by
  // R (1 - cos(theta / 2)).
  const double big_r = std::abs(speed / rate);
  const double s = chord_sagitta * radius / big_r;
  const double theta = s >= 1.0 ? chord_turn : std::min(chord_turn, 2.0 * std::acos(1.0 - s));
  const auto n = static_cast<std::size_t>(std::max(1.0, std::ceil(std::abs(drawn) / theta)));
  // The flight's closed form (field_flight.hpp): x(phi) = x0 + (v / w) (sin(phi) u + (1 - cos(phi)) J(u)),
  // u the heading at the start and J(u) its clockwise quarter turn.
  const sim::Vec2 u = sim::heading_unit(heading);
  const sim::Vec2 ju{u.y, -u.x};
  const double r_signed = speed / rate;
  std::vector<sim::Vec2> out;
  out.reserve(n);
  for (std::size_t k = 1; k < n; ++k) {
    const double phi = drawn * static_cast<double>(k) / static_cast<double>(n);
    const double h = std::sin(0.5 * phi);
    out.push_back(start + r_signed * (std::sin(phi) * u + (2.0 * h * h) * ju));
  }
  out.push_back(end);
  return out;
}

}  // namespace turtlegas::turtle::detail
