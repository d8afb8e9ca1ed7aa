// SPDX-License-Identifier: MIT
// The control-step grid, defined once: boundary k is at k * dt. The runtime wakes programs at these
// times and the engine ends a touched turtle's coast at the next one, so both read this header.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace turtlegas::sim {

/// The time of control boundary k: k * dt (one multiplication, so every caller gets the same double).
inline double control_boundary(std::uint64_t k, double dt) { return static_cast<double>(k) * dt; }

/// The index of the first boundary strictly after t (t >= 0, dt > 0): the smallest k with
/// control_boundary(k, dt) > t. The quotient t / dt only proposes k; the comparison is made on the
/// boundary times themselves, so a t that is itself a boundary (t == control_boundary(j, dt))
/// gives j + 1 whatever the rounding of t / dt.
inline std::uint64_t next_control_step(double t, double dt) {
  auto k = static_cast<std::uint64_t>(std::max(0.0, std::floor(t / dt)));
  while (k > 0 && control_boundary(k - 1, dt) > t) --k;
  while (control_boundary(k, dt) <= t) ++k;
  return k;
}

}  // namespace turtlegas::sim
