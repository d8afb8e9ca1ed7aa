// SPDX-License-Identifier: MIT
#include "cell_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "turtlegas/sim/format.hpp"

namespace turtlegas::sim::detail {
namespace {

// floor(x / cell) + 1 clamped to [lo, hi], decided in double: a coordinate of 1e30 (or a NaN)
// must not reach an int conversion, which would be undefined (a wall ending at y = 1e30 once
// landed in no cell at all and balls passed through it).
int clamped_index(double x, double cell, int lo, int hi) {
  const double k = std::floor(x / cell) + 1.0;
  if (!(k > lo)) return lo;
  if (!(k < hi)) return hi;
  return static_cast<int>(k);
}

// Cells along one side: floor(extent / min_cell), at least 1, decided in double (an arena 1e10
// wide with cells of 1e-10 overflows an int). kMaxCells bounds the product, so the clamp here
// only keeps the conversion defined.
int cells_along(double extent, double min_cell) {
  const double k = std::floor(extent / min_cell);
  if (!(k >= 1.0)) return 1;
  return k > 1e9 ? 1000000000 : static_cast<int>(k);
}

// The part of segment p->q inside the box [x0, x1] x [y0, y1] (Liang-Barsky), as parameters
// [t0, t1] along it; t0 > t1 when it misses the box.
std::pair<double, double> clip_to_box(Vec2 p, Vec2 q, double x0, double y0, double x1, double y1) {
  double t0 = 0.0, t1 = 1.0;
  const Vec2 d = q - p;
  const double pk[4] = {-d.x, d.x, -d.y, d.y};
  const double qk[4] = {p.x - x0, x1 - p.x, p.y - y0, y1 - p.y};
  for (int k = 0; k < 4; ++k) {
    if (pk[k] == 0.0) {
      if (qk[k] < 0.0) return {1.0, 0.0};
    } else {
      const double r = qk[k] / pk[k];
      if (pk[k] < 0.0) t0 = std::max(t0, r);
      else t1 = std::min(t1, r);
    }
  }
  return {t0, t1};
}

// Does segment p->q meet the closed box [x0, x1] x [y0, y1]?
bool segment_meets_box(Vec2 p, Vec2 q, double x0, double y0, double x1, double y1) {
  const auto [t0, t1] = clip_to_box(p, q, x0, y0, x1, y1);
  return t0 <= t1;
}

}  // namespace

CellGrid::CellGrid(double width, double height, double min_cell, bool periodic,
                   const std::vector<Segment>& walls, const std::vector<WallEnd>& ends,
                   const std::vector<bool>& skip)
    : width_(width), height_(height), periodic_(periodic) {
  const double nxd = std::max(1.0, std::floor(width / min_cell)), nyd = std::max(1.0, std::floor(height / min_cell));
  if (!((nxd + 2.0) * (nyd + 2.0) <= 2.0e8))
    throw std::invalid_argument("the grid would need more than 2e8 cells (" + format_number(nxd) + " x " +
                                format_number(nyd) + " of " + format_number(min_cell) +
                                "); set a larger arena.cell, or make arena.width and arena.height less unequal");
  nx_ = cells_along(width, min_cell);
  ny_ = cells_along(height, min_cell);
  cw_ = width / nx_;
  ch_ = height / ny_;
  for (int k = 0; k <= nx_ + 1; ++k) x_lines_.push_back(x_edge(k));
  for (int k = 0; k <= ny_ + 1; ++k) y_lines_.push_back(y_edge(k));
  for (int sy = 0; sy < 3; ++sy)
    for (int sx = 0; sx < 3; ++sx) shifts_[sy * 3 + sx] = {(sx - 1) * width, (sy - 1) * height};

  const auto n = static_cast<std::size_t>(cell_count());
  {
    // The memory budget, checked before anything is listed: 4 bytes a cell, and per wall about
    // length / cell + 2 cells crossed, each listed once in its own cell and nine times in the
    // neighbourhoods around it (a (cell, item) pair of 8 bytes while sorting, 12 once stored).
    double entries = 0.0, longest = 0.0;
    for (std::uint32_t w = 0; w < walls.size(); ++w) {
      if (w < skip.size() && skip[w]) continue;
      const Vec2 p = walls[w].p1, q = walls[w].p1 + walls[w].len * walls[w].u;
      const auto [t0, t1] = clip_to_box(p, q, -cw_, -ch_, width_ + cw_, height_ + ch_);
      if (!(t0 <= t1)) continue;
      const Vec2 d = (t1 - t0) * (q - p);
      const double crossed = std::min(std::abs(d.x) / cw_ + 2.0, nx_ + 2.0) + std::min(std::abs(d.y) / ch_ + 2.0, ny_ + 2.0);
      entries += 10.0 * crossed;
      longest = std::max(longest, walls[w].len);
    }
    entries += 10.0 * static_cast<double>(ends.size());
    const double bytes = 4.0 * static_cast<double>(n) + 12.0 * entries;
    if (bytes > kMemoryBudget)
      throw std::invalid_argument(
          "the grid would take " + format_number(std::round(bytes / 1e6)) + " MB (" + std::to_string(n) + " cells of " +
          format_number(cw_) + " x " + format_number(ch_) + ", about " + format_number(std::round(entries)) +
          " wall entries), over its budget of " + format_number(kMemoryBudget / 1e6) + " MB; set a larger arena.cell" +
          (12.0 * entries > 4.0 * static_cast<double>(n) ? " or shorten the longest wall (" + format_number(longest) + " long)"
                                                          : std::string()));
  }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> wl, el;
  // A little slack so that a wall running exactly along a grid line is listed on both sides.
  const double sx = 1e-9 * cw_, sy = 1e-9 * ch_;
  auto col = [&](double x) { return clamped_index(x, cw_, 0, nx_ + 1); };
  auto row = [&](double y) { return clamped_index(y, ch_, 0, ny_ + 1); };
  for (std::uint32_t w = 0; w < walls.size(); ++w) {
    if (w < skip.size() && skip[w]) continue;
    const Vec2 p = walls[w].p1, q = walls[w].p1 + walls[w].len * walls[w].u;
    // Only the part of a wall within one cell of the arena can be reached: bodies are inside the
    // arena (they exit an open one, walls stay in a periodic one) and no wider than a cell. The
    // rest is not listed (a wall 1e15 long rising slowly above a long thin arena was listed in
    // every cell of the ring above it, 3.7e6 of them: `check` took 60 s and 1.4 GB).
    const auto [t0, t1] = clip_to_box(p, q, -cw_, -ch_, width_ + cw_, height_ + ch_);
    if (!(t0 <= t1)) continue;
    const Vec2 cp = t0 > 0.0 ? p + t0 * (q - p) : p, cq = t1 < 1.0 ? p + t1 * (q - p) : q;
    const int ix0 = col(std::min(cp.x, cq.x) - sx), ix1 = col(std::max(cp.x, cq.x) + sx);
    const int iy0 = row(std::min(cp.y, cq.y) - sy), iy1 = row(std::max(cp.y, cq.y) + sy);
    for (int iy = iy0; iy <= iy1; ++iy)
      for (int ix = ix0; ix <= ix1; ++ix) {
        // Ring cells extend to infinity outward so that walls beyond the grid are still listed.
        const double x0 = ix == 0 ? -INFINITY : x_edge(ix - 1) - sx;
        const double x1 = ix == nx_ + 1 ? INFINITY : x_edge(ix) + sx;
        const double y0 = iy == 0 ? -INFINITY : y_edge(iy - 1) - sy;
        const double y1 = iy == ny_ + 1 ? INFINITY : y_edge(iy) + sy;
        if (segment_meets_box(p, q, x0, y0, x1, y1)) wl.emplace_back(index(ix, iy), w);
      }
  }
  for (std::uint32_t e = 0; e < ends.size(); ++e) el.emplace_back(index(col(ends[e].p.x), row(ends[e].p.y)), e);

  // Deduplicated 3x3 neighbourhoods of the arena cells: every listed item is pushed to the arena
  // cells around the cell that lists it, with the shift under which they see it.
  std::vector<std::pair<std::uint32_t, Near>> nw, ne;
  auto spread = [&](const std::vector<std::pair<std::uint32_t, std::uint32_t>>& src,
                    std::vector<std::pair<std::uint32_t, Near>>& out) {
    for (const auto& [cell, item] : src) {
      int ix = ix_of(static_cast<int>(cell)), iy = iy_of(static_cast<int>(cell));
      Vec2 base{};
      if (periodic_) {
        // A periodic arena has no ring: what a ring cell lists (a wall or a wall end on the seam
        // x = W or y = H, or on x = 0, y = 0 seen from below) is the arena cell across the seam's,
        // seen with that seam's shift. (Dropping it lost the walls and ends on the seam.)
        if (ix < 1) { ix += nx_; base.x = width_; }
        else if (ix > nx_) { ix -= nx_; base.x = -width_; }
        if (iy < 1) { iy += ny_; base.y = height_; }
        else if (iy > ny_) { iy -= ny_; base.y = -height_; }
      }
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          int jx = ix + dx, jy = iy + dy;
          Vec2 seen_shift = base;
          if (periodic_) {
            // The arena cell (jx, jy) sees this item across the seam with the opposite shift.
            if (jx < 1) { jx += nx_; seen_shift.x += width_; }
            else if (jx > nx_) { jx -= nx_; seen_shift.x -= width_; }
            if (jy < 1) { jy += ny_; seen_shift.y += height_; }
            else if (jy > ny_) { jy -= ny_; seen_shift.y -= height_; }
          }
          if (jx < 1 || jx > nx_ || jy < 1 || jy > ny_) continue;
          out.emplace_back(index(jx, jy), Near{item, shift_index(seen_shift)});
        }
    }
  };
  spread(wl, nw);
  spread(el, ne);
  // Periodic arenas: the ring cells' items again, folded into the arena cells across the seam
  // with their shift, for step mode's scans (which wrap onto arena cells only and so never read a
  // ring cell: a wall end on x = W was invisible to them).
  std::vector<std::pair<std::uint32_t, Near>> sw, se;
  auto fold = [&](const std::vector<std::pair<std::uint32_t, std::uint32_t>>& src,
                  std::vector<std::pair<std::uint32_t, Near>>& out) {
    if (!periodic_) return;
    for (const auto& [cell, item] : src) {
      int ix = ix_of(static_cast<int>(cell)), iy = iy_of(static_cast<int>(cell));
      if (ix >= 1 && ix <= nx_ && iy >= 1 && iy <= ny_) continue;
      Vec2 base{};
      if (ix < 1) { ix += nx_; base.x = width_; }
      else if (ix > nx_) { ix -= nx_; base.x = -width_; }
      if (iy < 1) { iy += ny_; base.y = height_; }
      else if (iy > ny_) { iy -= ny_; base.y = -height_; }
      out.emplace_back(index(ix, iy), Near{item, shift_index(base)});
    }
  };
  fold(wl, sw);
  fold(el, se);
  slot_.assign(n, 0);
  records_.assign(1, Ranges{});
  store(wl, wall_items_, &Ranges::walls);
  store(el, end_items_, &Ranges::ends);
  store(nw, near_walls_, &Ranges::near_walls);
  store(ne, near_ends_, &Ranges::near_ends);
  store(sw, seam_walls_, &Ranges::seam_walls);
  store(se, seam_ends_, &Ranges::seam_ends);
}

CellGrid::Ranges& CellGrid::record_for(std::uint32_t cell) {
  if (slot_[cell] == 0) {
    slot_[cell] = static_cast<std::uint32_t>(records_.size());
    records_.emplace_back();
  }
  return records_[slot_[cell]];
}

// Sorts (cell, item) pairs, drops repeats and lays them out as one contiguous range per cell.
template <class T>
void CellGrid::store(std::vector<std::pair<std::uint32_t, T>>& pairs, std::vector<T>& items,
                     std::uint32_t (Ranges::*range)[2]) {
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  items.clear();
  items.reserve(pairs.size());
  for (std::size_t k = 0; k < pairs.size();) {
    const std::uint32_t cell = pairs[k].first;
    const auto first = static_cast<std::uint32_t>(items.size());
    for (; k < pairs.size() && pairs[k].first == cell; ++k) items.push_back(pairs[k].second);
    Ranges& r = record_for(cell);
    (r.*range)[0] = first;
    (r.*range)[1] = static_cast<std::uint32_t>(items.size());
  }
  pairs.clear();
  pairs.shrink_to_fit();
}

int CellGrid::arena_cell_of(Vec2 p) const {
  const int ix = clamped_index(p.x, cw_, 1, nx_);
  const int iy = clamped_index(p.y, ch_, 1, ny_);
  return index(ix, iy);
}

std::uint32_t CellGrid::shift_index(Vec2 s) const {
  const int sx = s.x < 0.0 ? 0 : (s.x > 0.0 ? 2 : 1);
  const int sy = s.y < 0.0 ? 0 : (s.y > 0.0 ? 2 : 1);
  return static_cast<std::uint32_t>(sy * 3 + sx);
}

std::size_t CellGrid::memory_bytes() const {
  return sizeof(double) * (x_lines_.capacity() + y_lines_.capacity()) +
         sizeof(std::uint32_t) * (slot_.capacity() + wall_items_.capacity() + end_items_.capacity()) +
         sizeof(Ranges) * records_.capacity() + sizeof(Near) * (near_walls_.capacity() + near_ends_.capacity() + seam_walls_.capacity() + seam_ends_.capacity());
}

}  // namespace turtlegas::sim::detail
