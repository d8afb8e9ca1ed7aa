// SPDX-License-Identifier: MIT
// The region query (World::balls_in_rect): the balls in a rectangle, from the grid's cell lists.
//
// Which cells: those the rectangle overlaps, widened by `pad` cells on each side. A ball is listed
// in the cell of its centre as of its last event (exact mode: cell crossings keep that exact up to
// round-off at a cell's edge, so one cell of padding covers it) or of the step's start (step mode:
// it may have gone up to the step's longest path since, dmax, so the padding adds dmax in cells).
// Each listed ball is then tested exactly, at the present, so padding only costs the balls of the
// padded cells, never a wrong answer. Open arenas also look at the perimeter ring (balls just
// out, not yet exited). In a periodic arena the column and row ranges wrap, and a ball is in the
// rectangle when one of its images is (the test below); a range of nx columns or more is all of
// them, each once, so no ball is found twice. Cost: O(cells touched + balls in them).
#pragma once

namespace turtlegas::sim::detail {
namespace {

/// Whether coordinate x (in [0, period) up to round-off) has an image in [lo, hi].
inline bool image_in(double x, double lo, double hi, double period) {
  const double k = std::ceil((lo - x) / period);
  const double y = x + k * period;
  // y is the least image >= lo (round-off may leave it a hair below lo: check the next one too).
  return (y >= lo && y <= hi) || (y + period >= lo && y + period <= hi);
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::balls_in_rect(Vec2 lo, Vec2 hi, std::vector<std::uint32_t>& out) const {
  if (!(lo.x <= hi.x && lo.y <= hi.y)) return;
  const std::size_t first = out.size();
  int pad = 1;
  if constexpr (kStep) pad += static_cast<int>(std::ceil(step_.dmax / std::min(grid_.cell_w(), grid_.cell_h())));
  const bool periodic = arena_.periodic();
  const int nx = grid_.nx(), ny = grid_.ny();
  // Cell columns (ix) and rows (iy) to visit: arena cells 1..n, the ring 0 and n + 1.
  auto span = [&](double a, double b, double cell, int n, std::vector<int>& cols) {
    const double fa = std::floor(a / cell), fb = std::floor(b / cell);
    if (periodic) {
      if (!(fb - fa + 1 + 2 * pad < n)) {
        for (int k = 1; k <= n; ++k) cols.push_back(k);
        return;
      }
      for (auto k = static_cast<long long>(fa) - pad; k <= static_cast<long long>(fb) + pad; ++k)
        cols.push_back(static_cast<int>(((k % n) + n) % n) + 1);
      return;
    }
    // Open or walled: clamp into [0, n + 1] (the ring included).
    const double lo_k = std::max(fa + 1 - pad, 0.0), hi_k = std::min(fb + 1 + pad, static_cast<double>(n + 1));
    for (auto k = static_cast<int>(lo_k); k <= static_cast<int>(hi_k); ++k) cols.push_back(k);
  };
  std::vector<int> cols, rows;
  span(lo.x, hi.x, grid_.cell_w(), nx, cols);
  span(lo.y, hi.y, grid_.cell_h(), ny, rows);
  for (int iy : rows)
    for (int ix : cols) {
      for (std::uint32_t i = bodies_.head[static_cast<std::size_t>(grid_.index(ix, iy))]; i != kNone;
           i = bodies_.body[i].next) {
        const Body& b = bodies_.body[i];
        const Vec2 p = motion_.flight().pos(i, b.x, b.v, now_ - b.t);
        const bool in = periodic ? image_in(p.x, lo.x, hi.x, arena_.width) && image_in(p.y, lo.y, hi.y, arena_.height)
                                 : p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y;
        if (in) out.push_back(i);
      }
    }
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end());
}

}  // namespace
}  // namespace turtlegas::sim::detail
