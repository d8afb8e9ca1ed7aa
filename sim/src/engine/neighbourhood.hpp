// SPDX-License-Identifier: MIT
// Who a body looks at: the candidates of its prediction, found in the memo's table (CellGrid).
//   - exact mode: the 3x3 cells around the body's own, with the walls and ends near them, and
//     every moving wall (they are not in the table);
//   - step mode: as many rings of cells as the body and its neighbours can travel in the rest of
//     the step (the memo's rule makes that the 3x3 neighbourhood; a body sped up by a collision
//     inside the step widens the search instead of missing a partner);
//   - after a cell crossing (exact mode): only the strip of three cells that has just come into
//     the neighbourhood.
// Each candidate goes to its interaction's predict (interactions.hpp). The broad phase here, the
// narrow phase there: neither knows the other's details.
//
// Everything a prediction runs is forced inline, down to each interaction's predict: the Look
// they share must not have its address taken by a call, or GCC keeps it in memory and reloads its
// references after every store to the Pending (step mode ran 18 % slower that way: predict_wall
// out of line).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "../cell_grid.hpp"
#include "turtlegas/sim/format.hpp"
#include "interactions.hpp"
#include "room_views.hpp"

namespace turtlegas::sim::detail {
namespace {

/// The cell (ix, iy) as its exit times are measured: from the cell index rather than re-derived
/// from the position, so a body sitting on an edge by round-off is never assigned twice.
inline CellBox cell_box(const CellGrid& grid, int ix, int iy) {
  return {grid.x_line(ix - 1), grid.x_line(ix), grid.y_line(iy - 1), grid.y_line(iy)};
}

/// The bodies listed in one cell: balls (when the pair can collide) and turtles. Forced inline
/// with predict_ball_ball: these are the innermost loops of every prediction.
template <bool kBallBall, Flight F, bool kExtras>
[[gnu::always_inline]] inline void scan_cell(const Look<F, kExtras>& l, std::uint32_t i, const Body& bi, int cell,
                                             Vec2 shift, Pending& p) {
  const BodyStore& s = l.bodies;
  if (!l.is_turtle(i)) {
    if constexpr (kBallBall)
      for (std::uint32_t j = s.head[cell]; j != kNone; j = s.body[j].next) predict_ball_ball(l, i, bi, j, shift, p);
  } else if (s.balls() > 0) {  // a scene of turtles alone never reads the (empty) ball lists
    for (std::uint32_t j = s.head[cell]; j != kNone; j = s.body[j].next) predict_ball_from_turtle(l, i, bi, j, shift, p);
  }
  if constexpr (kExtras)
    for (std::uint32_t j = s.turtle_head[cell]; j != kNone; j = s.body[j].next) predict_turtle(l, i, bi, j, shift, p);
}

/// Exact mode: body i in arena cell (ix, iy).
template <bool kBallBall, Flight F, bool kExtras>
[[gnu::always_inline]] inline void look_around(const Look<F, kExtras>& l, const CellGrid& grid, std::uint32_t i,
                                               const Body& bi, int ix, int iy, Pending& p) {
  const BodyStore& s = l.bodies;
  if (grid.plain_neighbourhood(ix, iy)) {
    // Away from a periodic seam the 3x3 cells are three runs of three in the table.
    const int stride = grid.stride();
    if constexpr (kExtras) {
      // Scenes with turtles: the first body listed in each of the nine cells is asked for
      // before the scan walks the lists one by one (with many turtles each is a cache miss).
      for (int row = static_cast<int>(bi.cell) - stride - 1, dy = -1; dy <= 1; ++dy, row += stride)
        for (int dx = 0; dx <= 2; ++dx) {
          if (const std::uint32_t j = s.turtle_head[row + dx]; j != kNone) __builtin_prefetch(&s.body[j]);
          if (s.balls() == 0) continue;
          if (const std::uint32_t j = s.head[row + dx]; j != kNone) __builtin_prefetch(&s.body[j]);
        }
    }
    for (int row = static_cast<int>(bi.cell) - stride - 1, dy = -1; dy <= 1; ++dy, row += stride)
      for (int dx = 0; dx <= 2; ++dx) scan_cell<kBallBall>(l, i, bi, row + dx, Vec2{}, p);
  } else {
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const auto nb = grid.neighbour(ix, iy, dx, dy);
        scan_cell<kBallBall>(l, i, bi, nb.cell, nb.shift, p);
      }
  }
  for (auto it = grid.near_walls_begin(bi.cell); it != grid.near_walls_end(bi.cell); ++it)
    predict_wall(l, i, bi, it->item, grid.shift(it->shift), p);
  for (auto it = grid.near_ends_begin(bi.cell); it != grid.near_ends_end(bi.cell); ++it)
    predict_end(l, i, bi, it->item, grid.shift(it->shift), p);
  if constexpr (kExtras)
    for (std::uint32_t m = 0; m < l.schedule.movers.size(); ++m) predict_mover(l, i, bi, m, p);
}

/// Step mode: body i in arena cell (ix, iy) at internal time l.now of a step of length dt (the
/// step starts at internal zero). Keeps `step.dmax` up to date.
template <bool kBallBall, Flight F, bool kExtras>
[[gnu::always_inline]] inline void look_along_step(const Look<F, kExtras>& l, const CellGrid& grid, StepState& step,
                                                   double dt, std::uint32_t i, const Body& bi, int ix, int iy,
                                                   Pending& p) {
  // The memo's cell rule, widened to speed: a body whose path and radii reach `reach` in this
  // step looks `reach / cell + 1` cells each way. Counted in double and capped at the grid's size
  // (a reach past the arena scans the arena, no more: nothing there is further), so that no speed
  // overflows an int or scans cells that do not exist.
  const double cell = std::min(grid.cell_w(), grid.cell_h());
  const double cap = static_cast<double>(std::max(grid.nx(), grid.ny()) + 2);
  auto rings = [&](double reach) {
    const double k = std::floor(reach / cell) + 1.0;
    return static_cast<int>(k < cap ? k : cap);  // (a NaN reach takes the cap too)
  };
  const double step_end = dt;
  const double d_i = step.travel[i] + path_length(bi.v, step_end - l.now);
  step.dmax = std::max(step.dmax, d_i);
  const int kb = rings(bi.r + step.rmax + d_i + step.dmax);
  const int kw = rings(bi.r + d_i);
  const bool periodic = grid.periodic();
  if (periodic && (2 * kb + 1 > grid.nx() || 2 * kb + 1 > grid.ny()))
    throw std::runtime_error(
        "step mode: a body at speed " + format_number(norm(bi.v)) + " moves " + format_number(d_i) +
        " in one step (dt = " + format_number(dt) + "), and with the fastest body's " + format_number(step.dmax) +
        " its scan must reach " + std::to_string(kb) + " cells of " + format_number(cell) +
        " each way, more than this periodic arena's " + std::to_string(grid.nx()) + " x " + std::to_string(grid.ny()) +
        " cells hold (the cell rule: a scan of 2 k + 1 cells across at most, k = (r + r_max + both paths) / cell + 1);"
        " use a smaller dt or --mode exact");
  // Open or walled arenas: only the cells that exist (balls are listed in arena cells 1..n, walls
  // also in the ring of cells around the arena, 0 and n + 1).
  const int bx0 = periodic ? -kb : std::max(-kb, 1 - ix), bx1 = periodic ? kb : std::min(kb, grid.nx() - ix);
  const int by0 = periodic ? -kb : std::max(-kb, 1 - iy), by1 = periodic ? kb : std::min(kb, grid.ny() - iy);
  for (int dy = by0; dy <= by1; ++dy)
    for (int dx = bx0; dx <= bx1; ++dx) {
      const auto nb = grid.neighbour(ix, iy, dx, dy);
      scan_cell<kBallBall>(l, i, bi, nb.cell, nb.shift, p);
    }
  ++step.scan;
  const std::size_t walls = l.walls.segments.size();
  const int wx0 = periodic ? -kw : std::max(-kw, -ix), wx1 = periodic ? kw : std::min(kw, grid.nx() + 1 - ix);
  const int wy0 = periodic ? -kw : std::max(-kw, -iy), wy1 = periodic ? kw : std::min(kw, grid.ny() + 1 - iy);
  for (int dy = wy0; dy <= wy1; ++dy)
    for (int dx = wx0; dx <= wx1; ++dx) {
      const auto nb = grid.neighbour(ix, iy, dx, dy);
      const std::uint32_t s = grid.shift_index(nb.shift);
      for (auto it = grid.walls_begin(nb.cell); it != grid.walls_end(nb.cell); ++it) {
        std::uint32_t& st = step.stamp[*it * 9 + s];
        if (st == step.scan) continue;
        st = step.scan;
        predict_wall(l, i, bi, *it, nb.shift, p);
      }
      for (auto it = grid.ends_begin(nb.cell); it != grid.ends_end(nb.cell); ++it) {
        std::uint32_t& st = step.stamp[walls * 9 + *it * 9 + s];
        if (st == step.scan) continue;
        st = step.scan;
        predict_end(l, i, bi, *it, nb.shift, p);
      }
      if (!periodic) continue;
      // What the ring cells list, folded across the seam (CellGrid::seam_walls_begin).
      for (auto it = grid.seam_walls_begin(nb.cell); it != grid.seam_walls_end(nb.cell); ++it) {
        const Vec2 shift = nb.shift + grid.shift(it->shift);
        std::uint32_t& st = step.stamp[it->item * 9 + grid.shift_index(shift)];
        if (st == step.scan) continue;
        st = step.scan;
        predict_wall(l, i, bi, it->item, shift, p);
      }
      for (auto it = grid.seam_ends_begin(nb.cell); it != grid.seam_ends_end(nb.cell); ++it) {
        const Vec2 shift = nb.shift + grid.shift(it->shift);
        std::uint32_t& st = step.stamp[walls * 9 + it->item * 9 + grid.shift_index(shift)];
        if (st == step.scan) continue;
        st = step.scan;
        predict_end(l, i, bi, it->item, shift, p);
      }
    }
  if constexpr (kExtras)
    for (std::uint32_t m = 0; m < l.schedule.movers.size(); ++m) predict_mover(l, i, bi, m, p);
  if (p.t_coll > step_end) {
    p.t_coll = kNever;
    p.kind = Partner::none;
  }
}

/// After a crossing in `dir` (0 -x, 1 +x, 2 -y, 3 +y) into arena cell (ix, iy): the three cells
/// that have just come within the 3x3 neighbourhood. (Called from one place, cross().)
template <bool kBallBall, Flight F, bool kExtras>
[[gnu::always_inline]] inline void look_at_strip(const Look<F, kExtras>& l, const CellGrid& grid, std::uint32_t i, const Body& bi, int dir, int ix,
                   int iy, Pending& p) {
  const int ax = dir == 0 ? -1 : (dir == 1 ? 1 : 0);
  const int ay = dir == 2 ? -1 : (dir == 3 ? 1 : 0);
  int cells[3];
  Vec2 shifts[3] = {};
  if (grid.plain_neighbourhood(ix, iy)) {
    // Three cells in a row (step 1) or a column (step stride) of the table.
    const int step = ax != 0 ? grid.stride() : 1;
    const int middle = grid.index(ix + ax, iy + ay);
    cells[0] = middle - step;
    cells[1] = middle;
    cells[2] = middle + step;
  } else {
    for (int k = -1; k <= 1; ++k) {
      const auto nb = grid.neighbour(ix, iy, ax != 0 ? ax : k, ay != 0 ? ay : k);
      cells[k + 1] = nb.cell;
      shifts[k + 1] = nb.shift;
    }
  }
  for (int k = 0; k < 3; ++k) {
    const int cell = cells[k];
    scan_cell<kBallBall>(l, i, bi, cell, shifts[k], p);
    if (!grid.has_walls(cell)) continue;
    for (auto it = grid.walls_begin(cell); it != grid.walls_end(cell); ++it) predict_wall(l, i, bi, *it, shifts[k], p);
    for (auto it = grid.ends_begin(cell); it != grid.ends_end(cell); ++it) predict_end(l, i, bi, *it, shifts[k], p);
  }
}

}  // namespace
}  // namespace turtlegas::sim::detail
