// SPDX-License-Identifier: MIT
#include "turtlegas/sim/estimate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/cell_size.hpp"

namespace turtlegas::sim {
namespace {

double finite_or_max(double x) {
  if (std::isnan(x)) return std::numeric_limits<double>::max();
  return std::min(x, std::numeric_limits<double>::max());
}

}  // namespace

WorkEstimate estimate_work(const WorldDef& def, Mode mode, double until) {
  WorkEstimate w;
  const double width = def.arena.width, height = def.arena.height;
  const double side = std::max(std::min(width, height), 1e-300);
  const double area = std::max(width * height, 1e-300);
  const double g = std::hypot(def.effects.gravity.x, def.effects.gravity.y);
  // A ball falling across the arena gains sqrt(2 g H); use the larger side to be safe.
  const double fall = std::sqrt(2.0 * g * std::max(width, height));
  const std::size_t n = def.balls.size();
  double sum_speed = 0.0, rmax = 0.0, max_speed = 0.0;
  for (const BallDef& b : def.balls) {
    const double v = std::hypot(b.vel.x, b.vel.y) + fall;
    sum_speed += v;
    max_speed = std::max(max_speed, v);
    rmax = std::max(rmax, b.radius);
  }
  for (const TurtleDef& t : def.turtles) max_speed = std::max(max_speed, t.speed);
  w.max_speed = finite_or_max(max_speed);
  double cell = 0.0;
  try {
    cell = detail::choose_cell_size(def, mode);
  } catch (...) {
    cell = 2.0 * rmax;
  }
  cell = std::max(cell, 1e-300);
  const double density = static_cast<double>(n) / area;
  const double sigma = 2.0 * rmax;
  const double ball_ball = def.effects.ball_ball ? 0.5 * 2.0 * sigma * density * sum_speed : 0.0;  // pairs: half
  const double walls = sum_speed / side;
  w.collisions_per_s = finite_or_max(ball_ball + walls);
  w.crossings_per_s = mode == Mode::exact ? finite_or_max(sum_speed / cell) : 0.0;
  w.steps_per_s = mode == Mode::step ? finite_or_max(1.0 / def.dt) : 0.0;
  const double per_s = w.collisions_per_s + (mode == Mode::exact ? w.crossings_per_s : w.steps_per_s);
  w.events = finite_or_max(per_s * std::max(until, 0.0));
  return w;
}

}  // namespace turtlegas::sim
