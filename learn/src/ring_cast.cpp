// SPDX-License-Identifier: MIT
#include "ring_cast.hpp"

#include <algorithm>
#include <cmath>

namespace turtlegas::learn::detail {

bool RingCaster::applies(const sim::World& world, const sim::WorldDef& def, std::size_t max_walls) {
  if (def.arena.boundary == sim::Boundary::periodic) return false;
  const std::vector<sim::WallDef>& walls = world.walls();
  if (walls.size() > max_walls) return false;
  for (const sim::WallDef& w : walls)
    if (!w.keys.empty() || !w.visibility.empty()) return false;
  return true;
}

RingCaster::RingCaster(const sim::World& world, const sim::WorldDef& def) {
  const std::vector<sim::WallDef>& walls = world.walls();
  for (std::uint32_t w = 0; w < walls.size(); ++w) {
    segments_.push_back(sim::make_segment(walls[w].from, walls[w].to));  // as the engine builds its walls
    wall_layers_.push_back(walls[w].layers);
    // The ends as the engine keeps them (sim/src/engine/walls.cpp): one per distinct point, owned
    // by the first wall that ends there, with the union of those walls' layers.
    for (const sim::Vec2 p : {walls[w].from, walls[w].to}) {
      auto e = std::find_if(ends_.begin(), ends_.end(), [&](const End& x) { return x.p == p; });
      if (e == ends_.end()) {
        ends_.push_back({p, w, sim::Layers{0u, 0u}});
        e = ends_.end() - 1;
      }
      e->layers.category |= walls[w].layers.category;
      e->layers.mask |= walls[w].layers.mask;
    }
  }
  for (const sim::BallDef& b : def.balls) {
    ball_layers_.push_back(b.layers);
    max_ball_r_ = std::max(max_ball_r_, b.radius);
  }
  for (const sim::TurtleDef& t : def.turtles) turtle_layers_.push_back(t.layers);
}

void RingCaster::begin(const sim::World& world) {
  const std::size_t n = world.turtle_count();
  turtle_pos_.resize(n);
  turtle_r_.resize(n);
  turtle_alive_.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    turtle_alive_[j] = world.turtle_alive(j);
    if (!turtle_alive_[j]) continue;
    turtle_pos_[j] = world.turtle(j).pos;
    turtle_r_[j] = world.turtle_radius(j);
  }
}

void RingCaster::cast(const sim::World& world, sim::Vec2 o, const sim::Layers& layers, std::uint32_t self,
                      const std::vector<sim::Vec2>& dirs, const std::vector<double>& ranges, double reach,
                      std::vector<sim::RayHit>& out) {
  // The candidates: discs whose nearest point is within reach, walls whose line passes within
  // reach of the origin along their extent. Each test below is conservative, never exact.
  discs_.clear();
  walls_.clear();
  for (std::uint32_t j = 0; j < turtle_pos_.size(); ++j) {
    if (j == self || !turtle_alive_[j] || !layers.collides_with(turtle_layers_[j])) continue;
    const sim::Vec2 rel = turtle_pos_[j] - o;
    const double lim = reach + turtle_r_[j];
    if (std::fabs(rel.x) > lim || std::fabs(rel.y) > lim) continue;
    discs_.push_back({turtle_pos_[j], turtle_r_[j], sim::RayTarget::turtle, j});
  }
  if (!ball_layers_.empty() || world.ball_count() > 0) {
    const double lim = reach + max_ball_r_;
    balls_.clear();
    world.balls_in_rect(o - sim::Vec2{lim, lim}, o + sim::Vec2{lim, lim}, balls_);
    for (const std::uint32_t i : balls_) {
      const sim::Layers bl = i < ball_layers_.size() ? ball_layers_[i] : sim::Layers{};
      if (!layers.collides_with(bl)) continue;
      discs_.push_back({world.ball(i).pos, world.radius(i), sim::RayTarget::ball, i});
    }
  }
  for (std::uint32_t w = 0; w < segments_.size(); ++w) {
    if (!layers.collides_with(wall_layers_[w])) continue;
    const sim::Segment& s = segments_[w];
    const sim::Vec2 rel = o - s.p1;
    const double h = sim::dot(rel, s.n), foot = sim::dot(rel, s.u);
    if (std::fabs(h) > reach * 1.000001 + 1e-9 || foot < -reach * 1.000001 - 1e-9 || foot > s.len + reach * 1.000001 + 1e-9) continue;
    walls_.push_back(w);
  }
  near_ends_.clear();
  for (std::uint32_t e = 0; e < ends_.size(); ++e) {
    const sim::Vec2 rel = ends_[e].p - o;
    if (std::fabs(rel.x) > reach || std::fabs(rel.y) > reach || !layers.collides_with(ends_[e].layers)) continue;
    near_ends_.push_back(e);
  }
  out.resize(dirs.size());
  for (std::size_t k = 0; k < dirs.size(); ++k) {
    // As cast_ray: the direction normalised, hits beyond the range dropped, ties to the lower
    // (target, index).
    const sim::Vec2 u = dirs[k] / sim::norm(dirs[k]);
    const double range = ranges[k];
    sim::RayHit best;
    auto consider = [&](double d, sim::RayTarget target, std::uint32_t index) {
      if (!(d <= range)) return;
      if (d < best.distance || (d == best.distance && (target < best.target || (target == best.target && index < best.index))))
        best = {d, target, index};
    };
    for (const Disc& d : discs_) {
      const sim::Vec2 rel = d.pos - o;
      if (!(std::fabs(sim::cross(rel, u)) < d.r)) continue;
      consider(sim::ray_disc(rel, u, d.r), d.target, d.index);
    }
    for (const std::uint32_t w : walls_) {
      const sim::Segment& s = segments_[w];
      consider(sim::ray_segment(o - s.p1, u, s), sim::RayTarget::wall, w);
    }
    for (const std::uint32_t e : near_ends_) consider(sim::ray_point(o - ends_[e].p, u), sim::RayTarget::wall_end, ends_[e].wall);
    out[k] = best;
  }
}

}  // namespace turtlegas::learn::detail
