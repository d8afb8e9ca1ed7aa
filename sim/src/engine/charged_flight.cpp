// SPDX-License-Identifier: MIT
// ChargedFlight's species table and its cell exits (flights.hpp).
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <stdexcept>

#include "flights.hpp"
#include "turtlegas/sim/field_toi.hpp"

namespace turtlegas::sim::detail {

bool charges_feel_fields(const WorldDef& def) {
  const EffectsDef& fx = def.effects;
  if (fx.electric == Vec2{} && fx.magnetic == 0.0) return false;
  for (const BallDef& b : def.balls)
    if (b.charge != 0.0) return true;
  return false;
}

ChargedFlight::ChargedFlight(const WorldDef& def) {
  const EffectsDef& fx = def.effects;
  species_.push_back({fx.gravity, 0.0, false, kNever});  // species 0: uncharged
  of_.resize(def.balls.size(), 0);
  std::map<std::tuple<double, double, double>, std::uint32_t> index{{{fx.gravity.x, fx.gravity.y, 0.0}, 0}};
  bool charged = false;
  for (std::size_t i = 0; i < def.balls.size(); ++i) {
    const BallDef& b = def.balls[i];
    if (b.charge == 0.0) continue;
    charged = true;
    const double qm = b.charge / b.mass;
    Species s{fx.gravity + qm * fx.electric, qm * fx.magnetic};
    s.circle = s.w != 0.0 && s.a == Vec2{};
    s.period = gyration_period(s.w);
    const auto [it, added] = index.try_emplace({s.a.x, s.a.y, s.w}, static_cast<std::uint32_t>(species_.size()));
    if (added) species_.push_back(s);
    of_[i] = it->second;
  }
  // Pairs of different species, or a charged ball against a turtle, go to the bracketed search.
  std::size_t used = 0;
  std::vector<bool> seen(species_.size(), false);
  for (std::uint32_t k : of_)
    if (!seen[k]) {
      seen[k] = true;
      ++used;
    }
  bracketed_pairs_ = used > 1 || (charged && !def.turtles.empty());
  // One species of drift-free circles, fixed walls: every time of impact is a closed form exact
  // over any horizon (pairs: the rotation; faces and ends: the circle's), as with straight flights.
  bool moving_walls = false;
  for (const WallDef& w : def.walls) moving_walls = moving_walls || !w.keys.empty();
  closed_forms_ = !bracketed_pairs_ && !moving_walls;
  for (std::uint32_t k : of_) closed_forms_ = closed_forms_ && species_[k].w != 0.0 && species_[k].a == Vec2{};
}

CellExit ChargedFlight::cell_exit(std::uint32_t ball, Vec2 x, Vec2 v, const CellBox& b) const {
  const Species& s = species(ball);
  if (s.w == 0.0)
    return earlier_exit(axis_exit(x.x, v.x, s.a.x, b.x_lo, b.x_hi), axis_exit(x.y, v.y, s.a.y, b.y_lo, b.y_hi));
  const FieldFlight f{v, s.a, s.w};
  const double period = s.period;
  // The cell's searches look at most kPeriods ahead, then the body re-plans: a circle much smaller
  // than its cell, drifting slowly across a cell line, stays within reach of it for very many
  // periods, and the exact exit would be searched over all of them in one call.
  constexpr double kPeriods = 64.0;
  const double horizon = kPeriods * period;
  // While the circle's envelope (guiding centre +- gyration radius, moving at the drift) is
  // provably inside the cell, nothing needs computing: re-plan when that stops holding (never for a
  // drift-free circle inside its cell).
  // A circle wider than its cell (gyration radius, as flight_envelope forms it, at least 3/4 of the
  // cell's side, well clear of round-off) is never inside it: skip forming the envelope.
  // (A drift-free circle's radius is |v| / |w|: compared squared, without a root or a division.)
  const double side = 0.75 * std::min(b.x_hi - b.x_lo, b.y_hi - b.y_lo);
  const bool wider = s.circle ? dot(v, v) > (side * s.w) * (side * s.w)
                              : norm(field_acceleration(f)) / (f.w * f.w) > side;
  double quiet = 0.0;
  if (!wider) {
    const Envelope env = flight_envelope(x, f, 0.0);
    quiet = env.bounded ? quiet_time_box(env, {b.x_lo, b.y_lo}, {b.x_hi, b.y_hi}) : 0.0;
  }
  CellExit e;
  if (quiet > 0.0) {
    e = {quiet, kReplan};
  } else if (s.a == Vec2{}) {
    const BoxExit bx = field_box_exit_drift_free(x, f, {b.x_lo, b.y_lo}, {b.x_hi, b.y_hi});
    e = bx.t == kNever ? CellExit{horizon, kReplan}
                       : CellExit{bx.t, static_cast<std::uint8_t>(bx.axis == 0 ? (bx.upper ? 1 : 0) : (bx.upper ? 3 : 2))};
  } else {
    e = earlier_exit(field_axis_exit(x.x, f, 0, b.x_lo, b.x_hi, horizon), field_axis_exit(x.y, f, 1, b.y_lo, b.y_hi, horizon));
    if (e.t == kNever) e = {horizon, kReplan};
  }
  if (e.t == kNever && bracketed_pairs_) {
    // A circle that never leaves its cell: the bracketed pair searches need a finite horizon, so
    // it predicts afresh every few periods. (A scene of one species has only closed forms, which
    // need none.)
    e = {8.0 * period, kReplan};
  }
  // Never predict further than 2^30 periods: there an ulp of the time is 2^-22 of a period, and
  // the searches' pieces (half periods) are still resolved. Beyond some 2^50 periods they would not
  // be (t + piece == t), and the phase w t itself would be known to no better than a radian. A tiny
  // circle far from everything re-plans every 2^30 periods (0.7 s for a radius of 1e-10 at speed 1).
  const double cap = 0x1p30 * period;
  if (e.t > cap) e = {cap, kReplan};
  return e;
}

double ChargedFlight::toi_deforming_segment(std::uint32_t ball, Vec2 rel, Vec2 v, Vec2 d0, Vec2 w, double radius,
                                            double t_max) const {
  const Species& s = species(ball);
  if (s.w != 0.0)
    throw std::logic_error("a charged ball under a magnetic field met a rotating or deforming wall; validate() refuses such scenes");
  return toi_disc_deforming_segment(rel, v, s.a, d0, w, radius, t_max);
}

}  // namespace turtlegas::sim::detail
