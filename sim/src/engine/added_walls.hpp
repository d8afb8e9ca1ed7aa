// SPDX-License-Identifier: MIT
// Walls added while the world runs.
// Part of engine.hpp (members of Engine), included at its end.
#pragma once

namespace turtlegas::sim::detail {
namespace {

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::add_end_layers(Vec2 p, const Layers& l) {
  // An end is there for a body if any wall that ends there is.
  for (std::size_t e = 0; e < ends_.size(); ++e)
    if (ends_[e].p == p) {
      end_layers_[e].category |= l.category;
      end_layers_[e].mask |= l.mask;
      return;
    }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
std::size_t Engine<Flight, kBallBall, kStep, kExtras>::add_wall(const WallDef& wall) {
  const Vec2 d = wall.to - wall.from;
  if (!(norm2(d) > 0.0) || !is_finite(wall.from) || !is_finite(wall.to))
    throw std::invalid_argument("wall '" + wall.id + "' has zero length or a non-finite end; give it two distinct ends");
  if (!wall.keys.empty() || !wall.visibility.empty())
    throw std::invalid_argument("wall '" + wall.id + "': a wall added while the world runs cannot move or come and go (keys, visibility); put it in the scene");
  if (boundary_ == Boundary::periodic)
    for (Vec2 p : {wall.from, wall.to})
      if (p.x < 0.0 || p.x > width_ || p.y < 0.0 || p.y > height_)
        throw std::invalid_argument("wall '" + wall.id + "' reaches outside a periodic arena; keep walls inside it");
  if (2 * (walls_.size() + 1) > kMaxObjects)
    throw std::invalid_argument("wall '" + wall.id + "': too many walls (" + std::to_string(walls_.size()) +
                                "); the engine indexes wall ends with 29 bits");
  const Segment seg = make_segment(wall.from, wall.to);
  for (std::uint32_t i = 0; i < body_.size(); ++i) {
    const Body& b = body_[i];
    if (b.cell == kNone) continue;
    if constexpr (kExtras)
      if (!layers_[i].collides_with(wall.layers)) continue;  // it passes through this wall
    const Vec2 rel = rel_to_segment(pos_at(b, i, now_ - b.t), seg);
    const double foot = std::clamp(dot(rel, seg.u), 0.0, seg.len);
    const double gap = norm(rel - foot * seg.u) - b.r;
    if (gap < 0.0)
      throw std::invalid_argument("wall '" + wall.id + "' would overlap " + (is_turtle(i) ? "a turtle" : "a ball") +
                                  " (by " + std::to_string(-gap) + "); lay it clear of bodies");
  }
  // Append, so that the indices of walls and ends already named by predictions stay valid.
  const auto w = static_cast<std::uint32_t>(walls_.size());
  wall_defs_.push_back(wall);
  walls_.push_back(seg);
  for (Vec2 p : {wall.from, wall.to}) {
    const bool known = std::any_of(ends_.begin(), ends_.end(), [&](const WallEnd& e) { return e.p == p; });
    if (!known) {
      ends_.push_back({p, w});
      if constexpr (kExtras) end_layers_.push_back(Layers{0u, 0u});
    }
  }
  if constexpr (kExtras) {
    wall_layers_.push_back(wall.layers);
    base_mask_.push_back(wall.layers.mask);
    for (Vec2 p : {wall.from, wall.to}) add_end_layers(p, wall.layers);
  }
  mover_of_.push_back(kNone);
  std::vector<bool> moving(walls_.size());
  for (std::uint32_t k = 0; k < walls_.size(); ++k) moving[k] = mover_of_[k] != kNone;
  grid_ = CellGrid(width_, height_, cell_, grid_.periodic(), walls_, ends_, moving);  // same cells, new lists
  if constexpr (kStep) stamp_.assign(walls_.size() * 9 + ends_.size() * 9, 0);
  // Every prediction may now meet the new wall first.
  for (std::uint32_t i = 0; i < body_.size(); ++i) {
    if (body_[i].cell == kNone) continue;
    sync(i);
    repredict(i);
  }
  return w;
}

}  // namespace
}  // namespace turtlegas::sim::detail
