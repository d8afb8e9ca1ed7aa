// SPDX-License-Identifier: MIT
// The overlap measure (World::measure_overlap): how deep the deepest overlap of the scene is.
// Production code, independent of the engine's own grid; the test oracles are in reference.hpp.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "turtlegas/sim/toi.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim::detail {

/// Discs as the overlap check reads them: n of them, each read through these functions (so that
/// an engine need not copy its million bodies into arrays to be checked).
struct DiscView {
  std::size_t n = 0;
  std::function<Vec2(std::size_t)> pos;
  std::function<double(std::size_t)> radius;
  std::function<bool(std::size_t)> alive;
};

/// The buffers of the overlap measure, kept between measures so that a run measuring at many
/// instants allocates once: the live discs bucketed by cell (32 bytes a disc) and the buckets'
/// ends (4 bytes for each of at most 2 x bodies buckets).
struct OverlapScratch {
  struct Disc {
    Vec2 at;
    double r = 0.0;
    std::uint32_t id = 0;
  };
  std::vector<Disc> disc;
  std::vector<std::uint32_t> end;
  double cell = 0.0;  ///< the cell side of the last measure (2 x its largest radius)
};

namespace overlap {

inline Vec2 min_image(Vec2 d, double w, double h) {
  if (w > 0.0) d.x -= w * std::round(d.x / w);
  if (h > 0.0) d.y -= h * std::round(d.y / h);
  return d;
}

// floor(x / cell), clamped to +-2^62 in double first: a gas of radius 1e-22 has cell indices past
// int64's range (undefined behaviour once), and neighbours of a clamped index stay in range.
inline std::int64_t cell_index(double x, double cell) {
  const double k = std::floor(x / cell);
  constexpr double kMax = 0x1p62;
  if (!(k > -kMax)) return -static_cast<std::int64_t>(kMax);
  if (!(k < kMax)) return static_cast<std::int64_t>(kMax);
  return static_cast<std::int64_t>(k);
}

inline double distance_to_segment(Vec2 p, const Segment& s) {
  const Vec2 rel = p - s.p1;
  const double foot = std::clamp(dot(rel, s.u), 0.0, s.len);
  return norm(rel - foot * s.u);
}

/// The cells of side `cell` hashed into 2^k buckets: row-major cell numbers (rows `stride` cells
/// long) modulo the bucket count. Neighbours along a row are neighbouring buckets, so reading the
/// 3x3 cells around a disc reads three runs of memory; cells that share a bucket only add pairs
/// that are checked and found apart. In a periodic arena the cells tile it exactly (ncx x ncy of
/// them, each at least `cell` wide) and wrap.
struct Cells {
  double cell = 1.0, cell_w = 1.0, cell_h = 1.0;
  double width = 0.0, height = 0.0;  // periodic when > 0
  std::int64_t ncx = 0, ncy = 0;
  std::uint64_t stride = 1, mask = 0;

  std::pair<std::int64_t, std::int64_t> of(Vec2 p) const {
    if (width > 0.0) {
      p = {p.x - width * std::floor(p.x / width), p.y - height * std::floor(p.y / height)};
      return {std::clamp<std::int64_t>(cell_index(p.x, cell_w), 0, ncx - 1),
              std::clamp<std::int64_t>(cell_index(p.y, cell_h), 0, ncy - 1)};
    }
    return {cell_index(p.x, cell_w), cell_index(p.y, cell_h)};
  }
  std::uint32_t bucket(std::int64_t cx, std::int64_t cy) const {
    if (width > 0.0) {
      cx = cx < 0 ? cx + ncx : cx >= ncx ? cx - ncx : cx;
      cy = cy < 0 ? cy + ncy : cy >= ncy ? cy - ncy : cy;
    }
    // Unsigned arithmetic wraps modulo 2^64, which the bucket count divides: a valid hash for any
    // index, even the clamped +-2^62 of a gas spread past the doubles' cells.
    return static_cast<std::uint32_t>((static_cast<std::uint64_t>(cx) + static_cast<std::uint64_t>(cy) * stride) & mask);
  }
};

}  // namespace overlap

/// Deepest overlap among discs (ball-ball) and between discs and segments, found with a grid of
/// cells hashed into buckets (independent of the engine's grid): O(N) a measure, N the live
/// discs, plus N x walls for the walls. `pos(i)`, `radius(i)`, `alive(i)` read body i (each
/// position twice: it must give the same bits both times). Periodic arenas use the minimum image
/// when width/height are > 0. `row_hint`: the width of the scene in world units, for the buckets'
/// memory order (0: any). ball_pairs false checks discs against walls only. With layers given,
/// pairs whose collision layers do not meet are skipped (they may overlap).
template <class Pos, class Radius, class Alive>
Overlap deepest_overlap(OverlapScratch& s, std::size_t n, Pos&& pos, Radius&& radius, Alive&& alive,
                        const std::vector<Segment>& walls, double periodic_width, double periodic_height,
                        bool ball_pairs, const std::vector<Layers>* body_layers, const std::vector<Layers>* wall_layers,
                        double row_hint = 0.0) {
  using overlap::Cells;
  Overlap worst;
  auto note = [&](double depth, double r) {
    if (depth <= 0.0) return;
    worst.depth = std::max(worst.depth, depth);
    worst.relative = std::max(worst.relative, depth / r);
  };
  if (n == 0) return worst;
  // The buckets: about one per disc, a power of two (sized by all the bodies, so that the live
  // ones need not be counted in a pass of their own: each pass reads every body's record).
  const std::size_t buckets = std::bit_ceil(std::max<std::size_t>(n, 2));
  s.end.assign(buckets, 0);
  std::uint32_t live = 0;
  Cells c;
  c.width = periodic_width;
  c.height = periodic_height;
  c.mask = buckets - 1;
  auto shape = [&](double cell) {
    c.cell = c.cell_w = c.cell_h = cell;
    if (periodic_width > 0.0) {
      // Whole cells at least `cell` wide tile the arena, so that its cells wrap exactly.
      c.ncx = std::max<std::int64_t>(1, overlap::cell_index(periodic_width, cell));
      c.ncy = std::max<std::int64_t>(1, overlap::cell_index(periodic_height, cell));
      c.ncx = std::min<std::int64_t>(c.ncx, std::int64_t{1} << 31);
      c.ncy = std::min<std::int64_t>(c.ncy, std::int64_t{1} << 31);
      c.cell_w = periodic_width / static_cast<double>(c.ncx);
      c.cell_h = periodic_height / static_cast<double>(c.ncy);
      c.stride = static_cast<std::uint64_t>(c.ncx);
    } else {
      const double row = row_hint > 0.0 ? std::min(row_hint / cell, 0x1p31) : 0.0;
      c.stride = (row >= 1.0 ? static_cast<std::uint64_t>(row) + 2 : 1024) | 1;  // odd: rows never all collide
    }
  };
  // Pass 1: count the discs of each bucket, and the largest radius. The cell side of the last
  // measure is tried first; when a disc has grown past it, the count is done again.
  double rmax = 0.0;
  for (double cell = s.cell;;) {
    if (!(cell > 0.0)) {
      for (std::size_t i = 0; i < n; ++i)
        if (alive(i)) rmax = std::max(rmax, radius(i));
      cell = 2.0 * rmax;
      // Points only: nothing can overlap (a depth is a radius less a distance).
      if (!(cell > 0.0)) return worst;
    }
    shape(cell);
    rmax = 0.0;
    live = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!alive(i)) continue;
      ++live;
      rmax = std::max(rmax, radius(i));
      const auto [cx, cy] = c.of(pos(i));
      ++s.end[c.bucket(cx, cy)];
    }
    if (!(rmax > 0.0)) return worst;
    // Cells too small for the largest disc miss pairs; much larger ones only cost time.
    if (2.0 * rmax <= cell && 4.0 * rmax >= cell) break;
    cell = 2.0 * rmax;
    std::fill(s.end.begin(), s.end.end(), 0u);
  }
  s.cell = c.cell;
  s.disc.resize(live);
  // Pass 2: the discs in bucket order (end[k] ends up at the end of bucket k).
  std::uint32_t sum = 0;
  for (std::uint32_t& e : s.end) {
    sum += e;
    e = sum - e;  // the bucket's start, for now
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!alive(i)) continue;
    const Vec2 p = pos(i);
    const auto [cx, cy] = c.of(p);
    s.disc[s.end[c.bucket(cx, cy)]++] = {p, radius(i), static_cast<std::uint32_t>(i)};
  }

  const double pw = periodic_width, ph = periodic_height;
  if (!walls.empty()) {
    auto meet_wall = [&](std::uint32_t i, std::size_t w) {
      return !body_layers || !wall_layers || (*body_layers)[i].collides_with((*wall_layers)[w]);
    };
    for (const OverlapScratch::Disc& d : s.disc) {
      for (std::size_t w = 0; w < walls.size(); ++w) {
        const Segment& seg = walls[w];
        if (!meet_wall(d.id, w)) continue;
        double dist = 1e300;
        if (pw > 0.0) {
          // The nearest image of the disc to the segment, not to its first end: for a wall longer
          // than half the arena they differ (the first end's nearest image once hid a disc half
          // inside a wall on the seam).
          const Vec2 p = seg.p1 + overlap::min_image(d.at - seg.p1, pw, ph);
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
              dist = std::min(dist, overlap::distance_to_segment(p + Vec2{dx * pw, dy * ph}, seg));
        } else {
          dist = overlap::distance_to_segment(d.at, seg);
        }
        note(d.r - dist, d.r);
      }
    }
  }
  if (!ball_pairs) return worst;

  // Pass 3: every disc against the discs of the 3x3 cells around it, each pair once (the one of
  // the pair later in bucket order is met from the earlier: the neighbourhood is symmetric).
  const std::uint32_t* end = s.end.data();
  const OverlapScratch::Disc* disc = s.disc.data();
  for (std::uint32_t a = 0; a < live; ++a) {
    const OverlapScratch::Disc& d = disc[a];
    const auto [cx, cy] = c.of(d.at);
    for (std::int64_t dy = -1; dy <= 1; ++dy)
      for (std::int64_t dx = -1; dx <= 1; ++dx) {
        const std::uint32_t k = c.bucket(cx + dx, cy + dy);
        for (std::uint32_t b = std::max(k == 0 ? 0u : end[k - 1], a + 1); b < end[k]; ++b) {
          const OverlapScratch::Disc& e = disc[b];
          if (body_layers && !(*body_layers)[d.id].collides_with((*body_layers)[e.id])) continue;
          const Vec2 gap = pw > 0.0 ? overlap::min_image(e.at - d.at, pw, ph) : e.at - d.at;
          const double reach = d.r + e.r;
          // Most candidates are in other cells of the bucket or apart: no square root for them.
          if (norm2(gap) >= reach * reach) continue;
          note(reach - norm(gap), std::min(d.r, e.r));
        }
      }
  }
  return worst;
}

/// deepest_overlap through a DiscView, with buffers of its own (the tests' entry).
Overlap deepest_overlap(const DiscView& discs, const std::vector<Segment>& walls, double periodic_width = 0.0,
                        double periodic_height = 0.0, bool ball_pairs = true,
                        const std::vector<Layers>* body_layers = nullptr, const std::vector<Layers>* wall_layers = nullptr);

}  // namespace turtlegas::sim::detail
