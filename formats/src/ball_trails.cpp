// SPDX-License-Identifier: MIT
#include "turtlegas/formats/ball_trails.hpp"

#include <algorithm>
#include <cmath>

namespace turtlegas::formats {

BallTrails::BallTrails(const sim::WorldDef& def, double from, std::size_t max_balls)
    : from_(from),
      periodic_(def.arena.boundary == sim::Boundary::periodic),
      width_(def.arena.width),
      height_(def.arena.height) {
  const std::size_t n = std::min(max_balls, def.balls.size());
  const sim::EffectsDef& e = def.effects;
  for (std::size_t i = 0; i < n; ++i) {
    const sim::BallDef& b = def.balls[i];
    const double qm = b.charge / b.mass;
    mass_.push_back(b.mass);
    field_.push_back({{}, e.gravity + qm * e.electric, qm * e.magnetic});
  }
}

void BallTrails::start(const sim::World& world) {
  started_ = true;
  tracks_.resize(field_.size());
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    const sim::BallState b = world.ball(i);
    tracks_[i] = {b.pos, b.vel, world.time(), b.alive, {b.pos}};
  }
}

void BallTrails::fly(std::size_t i, double t) {
  Track& tr = tracks_[i];
  const double span = t - tr.t;
  if (!(span > 0.0) || !tr.alive) return;
  const sim::FieldFlight f{tr.v, field_[i].a, field_[i].w};
  // 48 points a turn of the gyration, 8 more when the path bends under an acceleration.
  const double turns = std::abs(f.w) * span / (2.0 * 3.14159265358979323846);
  const int k = static_cast<int>(std::min(4096.0, 1.0 + std::ceil(48.0 * turns) + (f.a == sim::Vec2{} ? 0.0 : 8.0)));
  for (int j = 1; j < k; ++j) tr.points.push_back(tr.x + sim::field_displacement(f, span * j / k));
  const sim::FieldState s = sim::field_advance(tr.x, f, span);
  tr.x = s.x;
  tr.v = s.v;
  tr.t = t;
  tr.points.push_back(tr.x);
}

void BallTrails::take(const std::vector<sim::Impulse>& batch) {
  if (!started_) return;
  for (const sim::Impulse& c : batch) {
    if (c.t < from_) continue;
    const bool pair = c.kind == sim::EventKind::ball_ball;
    for (int side = 0; side < (pair ? 2 : 1); ++side) {
      const std::size_t i = side == 0 ? c.a : c.b;
      if (i >= tracks_.size()) continue;
      fly(i, c.t);
      tracks_[i].v += (side == 0 ? 1.0 : -1.0) / mass_[i] * c.dp;
    }
  }
}

void BallTrails::finish(const sim::World& world) {
  if (!started_) return;
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    fly(i, world.time());
    // Whatever moved the ball without an impulse (the squeeze rule, an exit) ends its trail where
    // the world has it.
    const sim::BallState b = world.ball(i);
    if (b.alive && tracks_[i].alive && !periodic_) end_mismatch_ = std::max(end_mismatch_, norm(b.pos - tracks_[i].x));
    if (!periodic_ && b.alive && tracks_[i].alive) tracks_[i].points.back() = b.pos;
  }
}

std::vector<std::vector<sim::Vec2>> BallTrails::polylines() const {
  std::vector<std::vector<sim::Vec2>> out;
  for (const Track& tr : tracks_) {
    out.emplace_back();
    sim::Vec2 last{};
    for (std::size_t k = 0; k < tr.points.size(); ++k) {
      sim::Vec2 p = tr.points[k];
      if (periodic_) p = {p.x - width_ * std::floor(p.x / width_), p.y - height_ * std::floor(p.y / height_)};
      if (k > 0 && periodic_ && (std::abs(p.x - last.x) > width_ / 2 || std::abs(p.y - last.y) > height_ / 2))
        out.emplace_back();
      out.back().push_back(p);
      last = p;
    }
    if (out.back().size() < 2) out.pop_back();
  }
  return out;
}

}  // namespace turtlegas::formats
