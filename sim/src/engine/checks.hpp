// SPDX-License-Identifier: MIT
// Checks the engine offers on its state: the energy, and how deep the deepest overlap is.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "../overlap.hpp"
#include "room_views.hpp"

namespace turtlegas::sim::detail {
namespace {

/// Kinetic plus potential energy of ball i at internal time l.now (`field` as energy()'s).
template <Flight F, bool kExtras, class Field>
double ball_energy(const Look<F, kExtras>& l, const Field& field, std::uint32_t i) {
  const F& f = l.motion.flight();
  const Body& b = l.bodies.body[i];
  const double dt = l.now - b.t;
  const Vec2 x = f.pos(i, b.x, b.v, dt);
  const Vec2 v = f.vel(i, b.v, dt);
  const double m = l.bodies.mass[i];
  return 0.5 * m * norm2(v) + m * field.potential(i, x);
}

/// Kinetic plus potential energy of the balls still in the arena at internal time l.now. `field`
/// gives the potential per unit mass: the flight in exact mode, the kick in step mode.
template <Flight F, bool kExtras, class Field>
double energy(const Look<F, kExtras>& l, const Field& field) {
  double e = 0.0;
  for (std::uint32_t i = 0; i < l.bodies.balls(); ++i) {
    if (l.bodies.body[i].cell == kNone) continue;
    e += ball_energy(l, field, i);
  }
  return e;
}

/// The deepest overlap now among the pairs that can touch (deepest_overlap, with the walls where
/// they are now). `scratch` keeps its buffers from one measure to the next.
template <bool kBallBall, Flight F, bool kExtras>
Overlap measure_overlap(const Look<F, kExtras>& l, const Arena& arena, OverlapScratch& scratch) {
  // Read in place: no copy of the bodies (a million of them would add ~40 bytes a ball to the peak).
  const BodyStore& s = l.bodies;
  const std::size_t n = s.size();
  const std::uint32_t nb = s.balls();
  auto pos = [&](std::size_t i) { return l.motion.pos(s.body[i], static_cast<std::uint32_t>(i), l.now - s.body[i].t); };
  auto rad = [&](std::size_t i) { return s.body[i].r; };
  auto alive = [&](std::size_t i) { return s.body[i].cell != kNone; };
  const bool periodic = arena.periodic();
  std::vector<Segment> walls_now = l.walls.segments;
  for (const Mover& m : l.schedule.movers) walls_now[m.wall] = m.segment_at(l.walls.segments[m.wall], l.now);
  const std::vector<Layers>* body_layers = kExtras ? &s.layers : nullptr;
  const std::vector<Layers>* wall_layers = kExtras ? &l.walls.layers : nullptr;
  if (!kBallBall && nb > 0) {
    // Balls pass through each other by request: measure walls for everyone, and pairs among the
    // turtles and between turtles and balls.
    Overlap worst = deepest_overlap(scratch, n, pos, rad, alive, walls_now, periodic ? arena.width : 0.0,
                                    periodic ? arena.height : 0.0, false, body_layers, wall_layers);
    for (std::uint32_t t = nb; t < n; ++t) {
      if (!alive(t)) continue;
      for (std::uint32_t j = 0; j < n; ++j) {
        if (j == t || !alive(j) || (j >= nb && j < t) || !l.meets(t, j)) continue;
        const double depth = rad(t) + rad(j) - norm(arena.min_image(pos(j) - pos(t)));
        if (depth > worst.depth) worst.depth = depth;
        if (depth / std::min(rad(t), rad(j)) > worst.relative) worst.relative = depth / std::min(rad(t), rad(j));
      }
    }
    return worst;
  }
  return deepest_overlap(scratch, n, pos, rad, alive, walls_now, periodic ? arena.width : 0.0,
                         periodic ? arena.height : 0.0, true, body_layers, wall_layers, arena.width);
}

}  // namespace
}  // namespace turtlegas::sim::detail
