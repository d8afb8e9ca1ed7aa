// SPDX-License-Identifier: MIT
// Bit-for-bit comparisons of two runs (world_copy_test, world_state_test): the same events at the
// same times, and the same balls at the same time, every double's bits equal.
#pragma once

#include <cstring>
#include <vector>

#include "turtlegas/sim/world.hpp"

namespace turtlegas::test {

inline bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

inline bool same_events(const std::vector<sim::Event>& a, const std::vector<sim::Event>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!same_bits(a[i].t, b[i].t) || a[i].kind != b[i].kind || a[i].a != b[i].a || a[i].b != b[i].b) return false;
  return true;
}

/// The same time, and every ball alive or not alike with the same position and velocity.
inline bool same_balls(const sim::World& x, const sim::World& y) {
  if (x.ball_count() != y.ball_count() || !same_bits(x.time(), y.time())) return false;
  for (std::size_t i = 0; i < x.ball_count(); ++i) {
    const sim::BallState a = x.ball(i), b = y.ball(i);
    if (a.alive != b.alive || !same_bits(a.pos.x, b.pos.x) || !same_bits(a.pos.y, b.pos.y) ||
        !same_bits(a.vel.x, b.vel.x) || !same_bits(a.vel.y, b.vel.y))
      return false;
  }
  return true;
}

}  // namespace turtlegas::test
