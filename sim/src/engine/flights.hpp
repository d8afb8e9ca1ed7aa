// SPDX-License-Identifier: MIT
// Flights: how a ball moves between events.
#pragma once

#include <algorithm>

#include "turtlegas/sim/toi.hpp"

namespace turtlegas::sim::detail {

/// Straight-line flight: no field acts between events.
struct FreeFlight {
  static constexpr bool kAccelerates = false;
  Vec2 a{};
  Vec2 pos(Vec2 x, Vec2 v, double dt) const { return x + dt * v; }
  Vec2 vel(Vec2 v, double) const { return v; }
  static AxisExit exit(double x, double v, double lo, double hi) {
    if (v > 0.0) return {std::max(0.0, (hi - x) / v), true};
    if (v < 0.0) return {std::max(0.0, (lo - x) / v), false};
    return {};
  }
  AxisExit exit_x(double x, double v, double lo, double hi) const { return exit(x, v, lo, hi); }
  AxisExit exit_y(double y, double v, double lo, double hi) const { return exit(y, v, lo, hi); }
};

/// Parabolic flight under a uniform acceleration shared by all balls (gravity).
struct GravityFlight {
  static constexpr bool kAccelerates = true;
  Vec2 a{};
  Vec2 pos(Vec2 x, Vec2 v, double dt) const { return x + dt * v + (0.5 * dt * dt) * a; }
  Vec2 vel(Vec2 v, double dt) const { return v + dt * a; }
  AxisExit exit_x(double x, double v, double lo, double hi) const { return axis_exit(x, v, a.x, lo, hi); }
  AxisExit exit_y(double y, double v, double lo, double hi) const { return axis_exit(y, v, a.y, lo, hi); }
};

}  // namespace turtlegas::sim::detail
