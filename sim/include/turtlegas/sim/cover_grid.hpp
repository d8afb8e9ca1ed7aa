// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "turtlegas/sim/vec2.hpp"

namespace turtlegas::sim {

/// Squared distance from p to the segment a-b (a != b).
inline double segment_distance2(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const double t = std::clamp(dot(p - a, ab) / norm2(ab), 0.0, 1.0);
  return norm2(p - (a + t * ab));
}

/// Items (32-bit numbers whose meaning the caller keeps) listed in every cell of a uniform grid
/// that they cover, in linked cell lists: discs by their bounding box, segments by the cells they
/// cross. Two things that overlap always share a cell, so a query of the cells a disc covers sees
/// every item it could overlap (some more than once). Coordinates outside the grid fall into its
/// edge cells. Used where scenes are checked and built (validate(), the gas generator), not by the
/// engine, whose grid is the memo's.
class CoverGrid {
 public:
  /// The cells a box covers, inclusive.
  struct Range {
    int x0, x1, y0, y1;
    std::size_t cells() const {
      return static_cast<std::size_t>(x1 - x0 + 1) * static_cast<std::size_t>(y1 - y0 + 1);
    }
  };

  /// Cells of about `side` over [lo, hi], at most max_cells of them (larger cells then).
  CoverGrid(Vec2 lo, Vec2 hi, double side, std::size_t max_cells) : lo_(lo) {
    const double w = hi.x - lo.x, h = hi.y - lo.y;
    const double cap = static_cast<double>(max_cells);
    double nx = std::clamp(std::ceil(w / side), 1.0, cap);
    double ny = std::clamp(std::ceil(h / side), 1.0, cap);
    if (nx * ny > cap) {
      const double shrink = std::sqrt(nx * ny / cap);
      nx = std::max(1.0, std::floor(nx / shrink));
      ny = std::max(1.0, std::floor(ny / shrink));
    }
    nx_ = static_cast<int>(nx);
    ny_ = static_cast<int>(ny);
    sx_ = w / nx_;
    sy_ = h / ny_;
    head_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_), npos);
  }

  /// Room for this many more entries, so that the list never doubles (and briefly triples).
  void reserve(std::size_t entries) { entries_.reserve(entries_.size() + entries); }
  /// Frees the cell lists; cover and cell_of still work.
  void release_lists() {
    head_ = {};
    entries_ = {};
  }

  Range cover(Vec2 lo, Vec2 hi) const { return Range{cx(lo.x), cx(hi.x), cy(lo.y), cy(hi.y)}; }
  Range cover_disc(Vec2 c, double r) const { return cover(c - Vec2{r, r}, c + Vec2{r, r}); }
  /// The average number of cells a disc of radius r placed at random covers.
  double cells_per_disc(double r) const { return (1.0 + 2.0 * r / sx_) * (1.0 + 2.0 * r / sy_); }
  /// Row-major number of the cell holding p: sorting by it puts neighbours near each other.
  std::size_t cell_of(Vec2 p) const { return cell(cx(p.x), cy(p.y)); }

  void insert(int ix, int iy, std::uint32_t item) {
    const std::size_t c = cell(ix, iy);
    entries_.push_back(Entry{item, head_[c]});
    head_[c] = static_cast<std::uint32_t>(entries_.size() - 1);
  }
  void insert(Range r, std::uint32_t item) {
    for (int iy = r.y0; iy <= r.y1; ++iy)
      for (int ix = r.x0; ix <= r.x1; ++ix) insert(ix, iy, item);
  }
  /// Every cell the segment p-q crosses: column by column, the cells between the lowest and
  /// highest y it reaches in that column. The padding absorbs rounding at cell borders.
  void insert_segment(Vec2 p, Vec2 q, std::uint32_t item) {
    if (p.x > q.x) std::swap(p, q);
    const double pad = 1e-9 * (sx_ + sy_ + std::abs(q.x - p.x) + std::abs(q.y - p.y));
    const int x0 = cx(p.x - pad), x1 = cx(q.x + pad);
    for (int ix = x0; ix <= x1; ++ix) {
      double ya = p.y, yb = q.y;
      if (q.x > p.x) {
        const double slope = (q.y - p.y) / (q.x - p.x);
        const double xa = std::clamp(lo_.x + ix * sx_, p.x, q.x);
        const double xb = std::clamp(lo_.x + (ix + 1) * sx_, p.x, q.x);
        ya = ix == x0 ? p.y : p.y + slope * (xa - p.x);
        yb = ix == x1 ? q.y : p.y + slope * (xb - p.x);
      }
      const int y0 = cy(std::min(ya, yb) - pad), y1 = cy(std::max(ya, yb) + pad);
      for (int iy = y0; iy <= y1; ++iy) insert(ix, iy, item);
    }
  }

  /// Calls f(item) for every item in the cells of r (an item may be seen more than once).
  /// Stops and returns true as soon as f returns true.
  template <class F>
  bool any(Range r, F&& f) const {
    for (int iy = r.y0; iy <= r.y1; ++iy)
      for (int ix = r.x0; ix <= r.x1; ++ix)
        for (std::uint32_t e = head_[cell(ix, iy)]; e != npos; e = entries_[e].next)
          if (f(entries_[e].item)) return true;
    return false;
  }

 private:
  static constexpr std::uint32_t npos = std::numeric_limits<std::uint32_t>::max();
  struct Entry {
    std::uint32_t item;
    std::uint32_t next;
  };
  static int clamp_index(double u, int n) {
    // Written so that huge values cannot overflow the int conversion.
    if (!(u > 0.0)) return 0;
    if (u >= n - 1) return n - 1;
    return static_cast<int>(u);
  }
  int cx(double x) const { return clamp_index((x - lo_.x) / sx_, nx_); }
  int cy(double y) const { return clamp_index((y - lo_.y) / sy_, ny_); }
  std::size_t cell(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(ix);
  }

  Vec2 lo_;
  int nx_ = 1, ny_ = 1;
  double sx_ = 1.0, sy_ = 1.0;
  std::vector<std::uint32_t> head_;
  std::vector<Entry> entries_;
};

}  // namespace turtlegas::sim
