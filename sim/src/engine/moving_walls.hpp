// SPDX-License-Identifier: MIT
// Moving walls: keyframes and the motion between them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "turtlegas/sim/vec2.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim::detail {
namespace {

/// A moving wall's pose at a keyframe: its first end and the vector to its second.
struct MoverKey {
  double t = 0.0;  ///< scene time, seconds
  Vec2 p1;
  Vec2 d;
};

/// A wall moving through keyframes: between two poses each end moves in a straight line at
/// constant velocity. When both ends move alike (w == 0) the wall translates at u, and in its own
/// frame every flight is the usual one with v - u (closed forms); otherwise it turns and stretches
/// as well, and contacts with its interior are found by bracketed root finding.
struct Mover {
  std::uint32_t wall = 0;
  std::size_t next = 0;  ///< the keyframe it is heading for (keys.size(): it has stopped)
  Vec2 p1_ref;           ///< its first end at internal time t_ref
  Vec2 d_ref;            ///< second end minus first, at t_ref
  double t_ref = 0.0;
  Vec2 u{};              ///< the first end's velocity, units/s
  Vec2 w{};              ///< d(d_ref)/dt: the second end's velocity minus the first's
  bool rigid() const { return w.x == 0.0 && w.y == 0.0; }
};

/// A moving wall's keyframes as the engine keeps them (validate() has checked them). A span that
/// differs from the previous pose's by round-off only (1e-12 of its length) is taken as exactly
/// the previous one, so that a wall meant to translate runs on the translation's closed forms.
std::vector<MoverKey> mover_keys(const WallDef& wd) {
  std::vector<MoverKey> out;
  out.reserve(wd.keys.size());
  Vec2 d_prev = wd.to - wd.from;
  for (const WallKey& key : wd.keys) {
    Vec2 d = key.to - key.from;
    if (norm(d - d_prev) <= 1e-12 * norm(d_prev)) d = d_prev;
    out.push_back({key.t, key.from, d});
    d_prev = d;
  }
  return out;
}

}  // namespace
}  // namespace turtlegas::sim::detail
