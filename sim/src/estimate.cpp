// SPDX-License-Identifier: MIT
#include "turtlegas/sim/estimate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "engine/cell_size.hpp"

namespace turtlegas::sim {
namespace {

double finite_or_max(double x) {
  if (std::isnan(x)) return std::numeric_limits<double>::max();
  return std::min(x, std::numeric_limits<double>::max());
}

double length(Vec2 v) { return std::hypot(v.x, v.y); }

}  // namespace

void WorkEstimate::set_cell(double side) {
  if (!(side > 0.0)) return;
  cell = side;
  crossings_per_s = finite_or_max(speed_sum / cell);
  events_per_s = finite_or_max(crossings_per_s + replans_per_s);
  if (!(replans_per_s <= crossings_per_s)) cause = WorkCause::gyration;
  else if (fastest != kNoBody) cause = by_fields ? WorkCause::fields : WorkCause::speed;
  else cause = WorkCause::none;
  const double per_s = collisions_per_s + (mode == Mode::exact ? events_per_s : steps_per_s);
  events = finite_or_max(per_s * until);
}

WorkEstimate estimate_work(const WorldDef& def, Mode mode, double until, std::optional<double> cell) {
  WorkEstimate w;
  w.mode = mode;
  w.until = std::max(until, 0.0);
  const double width = def.arena.width, height = def.arena.height;
  const double extent = std::max(width, height);
  const double side = std::max(std::min(width, height), 1e-300);
  const double area = std::max(width * height, 1e-300);
  const double g = length(def.effects.gravity);
  const double e = length(def.effects.electric);
  double ball_speeds = 0.0, rmax = 0.0;
  for (std::size_t i = 0; i < def.balls.size(); ++i) {
    const BallDef& b = def.balls[i];
    // Energy bounds the speed a field can add while the ball crosses the arena: sqrt(2 a L).
    const double a = g + (b.mass > 0.0 ? std::abs(b.charge) * e / b.mass : 0.0);
    const double from_fields = std::sqrt(2.0 * a * extent);
    const double v = length(b.vel) + from_fields;
    ball_speeds += v;
    rmax = std::max(rmax, b.radius);
    if (!(v <= w.max_speed)) {  // also takes a NaN or infinite speed
      w.max_speed = v;
      w.fastest = i;
      w.by_fields = from_fields > length(b.vel);
    }
  }
  // Doubling is exact: the same sum as doubling each term.
  double speed_sum = 2.0 * ball_speeds;
  for (std::size_t i = 0; i < def.turtles.size(); ++i) {
    const TurtleDef& t = def.turtles[i];
    const double v = std::abs(t.speed) + std::abs(t.turn_rate) * t.radius;
    speed_sum += v;
    if (!(v <= w.max_speed)) {
      w.max_speed = v;
      w.fastest = def.balls.size() + i;
      w.by_fields = false;
    }
  }
  w.max_speed = finite_or_max(w.max_speed);
  w.speed_sum = finite_or_max(speed_sum);
  if (mode == Mode::exact && def.effects.magnetic != 0.0) {
    for (std::size_t i = 0; i < def.balls.size(); ++i) {
      const BallDef& b = def.balls[i];
      if (b.charge == 0.0 || !(b.mass > 0.0)) continue;
      const double turns = std::abs(b.charge * def.effects.magnetic / b.mass) / (2.0 * std::numbers::pi);
      w.replans_per_s += turns / 8.0;
      if (!(turns <= w.turns_per_s)) {
        w.turns_per_s = turns;
        w.gyrating = i;
      }
    }
    w.replans_per_s = finite_or_max(w.replans_per_s);
    w.turns_per_s = finite_or_max(w.turns_per_s);
  }
  if (mode == Mode::step || !def.turtles.empty()) w.steps_per_s = finite_or_max(1.0 / def.dt);
  const double density = static_cast<double>(def.balls.size()) / area;
  const double sigma = 2.0 * rmax;
  const double ball_ball = def.effects.ball_ball ? 0.5 * 2.0 * sigma * density * ball_speeds : 0.0;  // pairs: half
  w.collisions_per_s = finite_or_max(ball_ball + ball_speeds / side);
  double chosen = 0.0;
  if (cell) {
    chosen = *cell;
  } else {
    try {
      chosen = detail::choose_cell_size(def, mode);
    } catch (...) {
      chosen = 2.0 * rmax;
    }
  }
  w.set_cell(std::max(chosen, 1e-300));
  return w;
}

}  // namespace turtlegas::sim
