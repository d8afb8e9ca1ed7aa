// SPDX-License-Identifier: MIT
// The overlap measure: World::measure_overlap, and through it the CLI's max_overlap and expect's.
#include "overlap.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

namespace turtlegas::sim::detail {
namespace {

Vec2 min_image(Vec2 d, double w, double h) {
  if (w > 0.0) d.x -= w * std::round(d.x / w);
  if (h > 0.0) d.y -= h * std::round(d.y / h);
  return d;
}

constexpr double kNeverDistance = 1e300;

// floor(x / cell), clamped to +-2^62 in double first: a gas of radius 1e-22 has cell indices past
// int64's range (undefined behaviour once), and neighbours of a clamped index stay in range.
std::int64_t cell_index(double x, double cell) {
  const double k = std::floor(x / cell);
  constexpr double kMax = 0x1p62;
  if (!(k > -kMax)) return -static_cast<std::int64_t>(kMax);
  if (!(k < kMax)) return static_cast<std::int64_t>(kMax);
  return static_cast<std::int64_t>(k);
}

double distance_to_segment(Vec2 p, const Segment& s) {
  const Vec2 rel = p - s.p1;
  const double foot = std::clamp(dot(rel, s.u), 0.0, s.len);
  return norm(rel - foot * s.u);
}

}  // namespace

Overlap deepest_overlap(const DiscView& discs, const std::vector<Segment>& walls, double periodic_width, double periodic_height,
                        bool ball_pairs, const std::vector<Layers>* body_layers, const std::vector<Layers>* wall_layers) {
  auto meet = [&](std::size_t i, std::size_t j) { return !body_layers || (*body_layers)[i].collides_with((*body_layers)[j]); };
  auto meet_wall = [&](std::size_t i, std::size_t w) {
    return !body_layers || !wall_layers || (*body_layers)[i].collides_with((*wall_layers)[w]);
  };
  Overlap worst;
  auto note = [&](double depth, double r) {
    if (depth <= 0.0) return;
    worst.depth = std::max(worst.depth, depth);
    worst.relative = std::max(worst.relative, depth / r);
  };
  const std::size_t n = discs.n;
  double rmax = 0.0;
  std::size_t live = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (discs.alive(i)) {
      rmax = std::max(rmax, discs.radius(i));
      ++live;
    }
  if (rmax == 0.0) return worst;

  for (std::size_t i = 0; i < n; ++i) {
    if (!discs.alive(i)) continue;
    const double r = discs.radius(i);
    const Vec2 at_i = walls.empty() ? Vec2{} : discs.pos(i);
    for (std::size_t w = 0; w < walls.size(); ++w) {
      const Segment& s = walls[w];
      if (!meet_wall(i, w)) continue;
      Vec2 p = at_i;
      double dist = kNeverDistance;
      if (periodic_width > 0.0) {
        // The nearest image of the disc to the segment, not to its first end: for a wall longer
        // than half the arena they differ (the first end's nearest image once hid a disc half
        // inside a wall on the seam).
        p = s.p1 + min_image(p - s.p1, periodic_width, periodic_height);
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            dist = std::min(dist, distance_to_segment(p + Vec2{dx * periodic_width, dy * periodic_height}, s));
      } else {
        dist = distance_to_segment(p, s);
      }
      note(r - dist, r);
    }
  }
  if (!ball_pairs) return worst;

  // Sort by cell of side 2 rmax and compare with the 3x3 neighbouring cells: an independent grid.
  // Each disc's position and cell are read once: the sampled self-check of a run measures often,
  // and reading them through the views at every comparison cost ten times more. The cells are
  // kept in 32-bit indices when every one fits (12 bytes a disc, with the 16 of its position:
  // the measure's peak stays under the engine's own 128 + bytes a ball at N = 10^6); a gas spread
  // past them (a fuzzed scene) takes 64-bit ones.
  const double cell = 2.0 * rmax;
  auto cell_of = [&](Vec2 p) {
    if (periodic_width > 0.0) p = {p.x - periodic_width * std::floor(p.x / periodic_width),
                                   p.y - periodic_height * std::floor(p.y / periodic_height)};
    return std::pair{cell_index(p.x, cell), cell_index(p.y, cell)};
  };
  std::vector<Vec2> at(n);
  constexpr std::int64_t kNarrow = std::int64_t{1} << 30;
  bool narrow = true;
  for (std::size_t i = 0; i < n; ++i)
    if (discs.alive(i)) {
      at[i] = discs.pos(i);
      const auto [cx, cy] = cell_of(at[i]);
      narrow = narrow && cx > -kNarrow && cx < kNarrow && cy > -kNarrow && cy < kNarrow;
    }
  const std::int64_t ncx = periodic_width > 0.0 ? cell_index(periodic_width, cell) : 0;
  const std::int64_t ncy = periodic_height > 0.0 ? cell_index(periodic_height, cell) : 0;
  auto check_pair = [&](std::size_t i, std::size_t j) {
    if (!meet(i, j)) return;
    const Vec2 d = min_image(at[j] - at[i], periodic_width, periodic_height);
    const double ri = discs.radius(i), rj = discs.radius(j);
    note(ri + rj - norm(d), std::min(ri, rj));
  };
  auto pairs = [&](auto index) {
    using Index = decltype(index);
    struct Cell {
      Index cx, cy;
      auto operator<=>(const Cell&) const = default;
    };
    struct Item {
      Cell c;
      std::uint32_t i;
    };
    std::vector<Item> order;
    order.reserve(live);
    for (std::size_t i = 0; i < n; ++i)
      if (discs.alive(i)) {
        const auto [cx, cy] = cell_of(at[i]);
        order.push_back({{static_cast<Index>(cx), static_cast<Index>(cy)}, static_cast<std::uint32_t>(i)});
      }
    std::sort(order.begin(), order.end(), [](const Item& a, const Item& b) { return a.c != b.c ? a.c < b.c : a.i < b.i; });
    const bool brute = periodic_width > 0.0 && (ncx < 3 || ncy < 3);
    if (brute || order.size() < 64) {
      for (std::size_t a = 0; a < order.size(); ++a)
        for (std::size_t b = a + 1; b < order.size(); ++b) check_pair(order[a].i, order[b].i);
      return;
    }
    for (const Item& home : order) {
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          std::int64_t cx = home.c.cx + dx, cy = home.c.cy + dy;
          if (periodic_width > 0.0) {
            // Cells past the last whole one belong to the last; wrap the rest.
            cx = ((cx % (ncx + 1)) + (ncx + 1)) % (ncx + 1);
            cy = ((cy % (ncy + 1)) + (ncy + 1)) % (ncy + 1);
          }
          const Cell c{static_cast<Index>(cx), static_cast<Index>(cy)};
          auto it = std::partition_point(order.begin(), order.end(), [&](const Item& k) { return k.c < c; });
          for (; it != order.end() && it->c == c; ++it)
            if (it->i > home.i) check_pair(home.i, it->i);
        }
    }
  };
  if (narrow && ncx < kNarrow && ncy < kNarrow) pairs(std::int32_t{});
  else pairs(std::int64_t{});
  return worst;
}

}  // namespace turtlegas::sim::detail
