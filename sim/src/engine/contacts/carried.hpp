// SPDX-License-Identifier: MIT
// Mechanism 5 of the contacts room (contacts.hpp): carried turtles. A turtle stops dead at a
// contact; one that a translating moving wall pushes cannot (both have infinite mass): it used to
// stop, be caught by the wall at once and meet its partner again, for ever at one instant. So a
// wall's push carries it along at the wall's normal speed until the wall's next keyframe, and a
// carried turtle pushes a turtle it meets along with it, carried by the same wall through it
// (docs/physics.md, "Wedged and crushed bodies"). The marks are Turtles::pushed_by and
// Turtles::pushed_via (turtle_motion.hpp); they are set here, read here, and end here.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "../room_views.hpp"
#include "contacts.hpp"

namespace turtlegas::sim::detail {

/// Turtle k (its body b) is now pushed by mover `mover`, through turtle `via` (kNone: the mover's
/// wall itself), at velocity v.
inline void carry(Turtles& turtles, std::size_t k, Body& b, Vec2 v, std::uint32_t mover, std::uint32_t via) {
  b.v = v;
  turtles.pushed_by[k] = mover;
  turtles.pushed_via[k] = via;
}

/// At a keyframe of some moving walls (`keyed`, per mover): turtle k's push ends with the segment
/// of motion that made it, and the turtle (its body b, brought to now) stands where it is. Another
/// wall's keyframe changes nothing: the push goes on. Returns whether the push ended.
inline bool push_ends(Turtles& turtles, std::size_t k, Body& b, const std::vector<std::uint8_t>& keyed) {
  if (turtles.pushed_by[k] == kNone || !keyed[turtles.pushed_by[k]]) return false;
  b.v = {};
  turtles.pushed_by[k] = kNone;
  turtles.pushed_via[k] = kNone;
  ++b.count;
  return true;
}

/// Whether turtle `id` is carried (Turtles::pushed_by): by a translating moving wall, or by a
/// turtle so carried, that still touches it (touch_gap) and still pushes it; then `v` is the
/// velocity it is carried at (the pusher's normal speed, along the normal). Such a turtle cannot
/// stop dead at a touch as a driving one does: what pushes it has infinite mass. The chain of
/// pushers is at most as long as there are turtles (`depth`).
template <Flight F, bool kStep, bool kExtras>
inline bool carried(const Parts<F, kStep, kExtras>& p, std::uint32_t id, Vec2& v, std::size_t depth = 0) {
  const BodyStore& bodies = p.bodies;
  const Turtles& turtles = p.turtles;
  const double now = p.now;
  const std::uint32_t nb = bodies.balls();
  const std::size_t k = id - nb;
  if (id < nb || k >= turtles.pushed_by.size() || turtles.pushed_by[k] == kNone || depth > turtles.size()) return false;
  const Body& b = bodies.body[id];
  const Vec2 x = b.x + (now - b.t) * b.v;  // (a turtle flies straight)
  Vec2 n, u;
  double gap = 0.0;
  if (const std::uint32_t via = turtles.pushed_via[k]; via == kNone) {
    const Mover& m = p.schedule.movers[turtles.pushed_by[k]];
    if (!m.rigid()) return false;  // a turning wall knocks a turtle off instead (apply_wall)
    const Segment s = m.segment_at(p.walls.segments[m.wall], now);
    const Vec2 rel = p.arena.rel_to_segment(x, s);
    const Vec2 off = rel - std::clamp(dot(rel, s.u), 0.0, s.len) * s.u;
    const double dist = norm(off);
    if (!(dist > 0.0)) return false;
    n = off / dist;
    gap = dist - b.r;
    u = m.u;
  } else {
    const std::uint32_t j = nb + via;
    if (!carried(p, j, u, depth + 1)) return false;
    const Body& bj = bodies.body[j];
    const Vec2 d = p.arena.min_image(x - (bj.x + (now - bj.t) * bj.v));
    const double dist = norm(d);
    if (!(dist > 0.0)) return false;
    n = d / dist;
    gap = dist - b.r - bj.r;
  }
  const double un = dot(u, n);
  if (!touching(gap, b.r, x) || !(un > 0.0)) return false;
  v = un * n;
  return true;
}

}  // namespace turtlegas::sim::detail
