// SPDX-License-Identifier: MIT
// The arena as the engine sees it: its size and boundary, and the minimum image of a periodic one.
#pragma once

#include <algorithm>
#include <cmath>

#include "turtlegas/sim/toi.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim::detail {

struct Arena {
  double width = 0.0;
  double height = 0.0;
  Boundary boundary = Boundary::none;

  bool periodic() const { return boundary == Boundary::periodic; }
  ArenaDef def() const {
    ArenaDef a;
    a.width = width;
    a.height = height;
    a.boundary = boundary;
    return a;
  }
  bool contains(Vec2 p) const { return !(p.x < 0.0 || p.x > width || p.y < 0.0 || p.y > height); }

  /// The image of d nearest to zero.
  Vec2 min_image(Vec2 d) const {
    if (periodic()) {
      // The arena is at least 3 cells (so 3 diameters) across: the nearest image is the one.
      d.x -= width * std::round(d.x / width);
      d.y -= height * std::round(d.y / height);
    }
    return d;
  }
  /// x - s.p1 for the image of x nearest to the segment. In a periodic arena the minimum image
  /// relative to p1 is the wrong one near the far part of a wall longer than half the arena.
  Vec2 rel_to_segment(Vec2 x, const Segment& s) const {
    Vec2 best = min_image(x - s.p1);
    if (!periodic()) return best;
    auto distance = [&](Vec2 rel) { return norm(rel - std::clamp(dot(rel, s.u), 0.0, s.len) * s.u); };
    double best_distance = distance(best);
    const Vec2 base = best;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const Vec2 rel = base + Vec2{dx * width, dy * height};
        const double d = distance(rel);
        if (d < best_distance) {
          best = rel;
          best_distance = d;
        }
      }
    return best;
  }
};

}  // namespace turtlegas::sim::detail
