// SPDX-License-Identifier: MIT
// Who a body looks at: the 3x3 scan (exact mode), the rings of step mode, the strip after a crossing, and the cell exit.
// Part of engine.hpp (members of Engine), included at its end.
#pragma once

namespace turtlegas::sim::detail {
namespace {

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
inline void Engine<Flight, kBallBall, kStep, kExtras>::scan_cell(std::uint32_t i, const Body& bi, int cell, Vec2 shift,
                                                           Pending& p) const {
  // The bodies listed in one cell: balls (when the pair can collide) and turtles.
  if (!is_turtle(i)) {
    if constexpr (kBallBall)
      for (std::uint32_t j = head_[cell]; j != kNone; j = body_[j].next) consider_ball(i, bi, j, shift, p);
  } else if (nb_ > 0) {  // a scene of turtles alone never reads the (empty) ball lists
    for (std::uint32_t j = head_[cell]; j != kNone; j = body_[j].next) consider_ball_from_turtle(i, bi, j, shift, p);
  }
  if constexpr (kExtras)
    for (std::uint32_t j = turtle_head_[cell]; j != kNone; j = body_[j].next) consider_turtle(i, bi, j, shift, p);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::predict(std::uint32_t i, int ix, int iy) {
  const Body& bi = body_[i];
  Pending& p = pending_[i];
  // A turtle's command end is not a candidate here: it is kept apart (command_end()), so that a
  // turtle whose command starts or ends without moving it keeps the collisions predicted for it.
  p.t_coll = kNever;
  p.kind = Partner::none;
  if constexpr (!kStep) {
    if (grid_.plain_neighbourhood(ix, iy)) {
      // Away from a periodic seam the 3x3 cells are three runs of three in the table.
      const int stride = grid_.stride();
      if constexpr (kExtras) {
        // Scenes with turtles: the first body listed in each of the nine cells is asked for
        // before the scan walks the lists one by one (with many turtles each is a cache miss).
        for (int row = static_cast<int>(bi.cell) - stride - 1, dy = -1; dy <= 1; ++dy, row += stride)
          for (int dx = 0; dx <= 2; ++dx) {
            if (const std::uint32_t j = turtle_head_[row + dx]; j != kNone) __builtin_prefetch(&body_[j]);
            if (nb_ == 0) continue;
            if (const std::uint32_t j = head_[row + dx]; j != kNone) __builtin_prefetch(&body_[j]);
          }
      }
      for (int row = static_cast<int>(bi.cell) - stride - 1, dy = -1; dy <= 1; ++dy, row += stride)
        for (int dx = 0; dx <= 2; ++dx) scan_cell(i, bi, row + dx, Vec2{}, p);
    } else {
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto nb = grid_.neighbour(ix, iy, dx, dy);
          scan_cell(i, bi, nb.cell, nb.shift, p);
        }
    }
    for (auto it = grid_.near_walls_begin(bi.cell); it != grid_.near_walls_end(bi.cell); ++it)
      consider_wall(i, bi, it->item, grid_.shift(it->shift), p);
    for (auto it = grid_.near_ends_begin(bi.cell); it != grid_.near_ends_end(bi.cell); ++it)
      consider_end(i, bi, it->item, grid_.shift(it->shift), p);
    if constexpr (kExtras)
      for (std::uint32_t m = 0; m < movers_.size(); ++m) consider_mover(i, bi, m, p);
  } else {
    // The memo's rule normally makes this the 3x3 neighbourhood; a body sped up by a collision
    // inside the step widens the search instead of missing a partner.
    const double step_end = dt_;
    const double d_i = travel_[i] + path_length(bi.v, step_end - now_);
    dmax_ = std::max(dmax_, d_i);
    const int kb = step_rings(bi.r + rmax_ + d_i + dmax_);
    const int kw = step_rings(bi.r + d_i);
    const bool periodic = grid_.periodic();
    if (periodic && (2 * kb + 1 > grid_.nx() || 2 * kb + 1 > grid_.ny()))
      throw std::runtime_error("step mode: a body moves too far in one step for this periodic arena; use a smaller dt or --mode exact");
    for (int dy = -kb; dy <= kb; ++dy)
      for (int dx = -kb; dx <= kb; ++dx) {
        if (!periodic && (ix + dx < 1 || ix + dx > grid_.nx() || iy + dy < 1 || iy + dy > grid_.ny())) continue;
        const auto nb = grid_.neighbour(ix, iy, dx, dy);
        scan_cell(i, bi, nb.cell, nb.shift, p);
      }
    ++scan_;
    for (int dy = -kw; dy <= kw; ++dy)
      for (int dx = -kw; dx <= kw; ++dx) {
        if (!periodic && (ix + dx < 0 || ix + dx > grid_.nx() + 1 || iy + dy < 0 || iy + dy > grid_.ny() + 1)) continue;
        const auto nb = grid_.neighbour(ix, iy, dx, dy);
        const std::uint32_t s = grid_.shift_index(nb.shift);
        for (auto it = grid_.walls_begin(nb.cell); it != grid_.walls_end(nb.cell); ++it) {
          std::uint32_t& st = stamp_[*it * 9 + s];
          if (st == scan_) continue;
          st = scan_;
          consider_wall(i, bi, *it, nb.shift, p);
        }
        for (auto it = grid_.ends_begin(nb.cell); it != grid_.ends_end(nb.cell); ++it) {
          std::uint32_t& st = stamp_[walls_.size() * 9 + *it * 9 + s];
          if (st == scan_) continue;
          st = scan_;
          consider_end(i, bi, *it, nb.shift, p);
        }
      }
    if constexpr (kExtras)
      for (std::uint32_t m = 0; m < movers_.size(); ++m) consider_mover(i, bi, m, p);
    if (p.t_coll > step_end) {
      p.t_coll = kNever;
      p.kind = Partner::none;
    }
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::predict_strip(std::uint32_t i, int dir, int ix, int iy) {
  // The three cells that have just come within the 3x3 neighbourhood after a crossing in `dir`.
  const Body& bi = body_[i];
  Pending& p = pending_[i];
  const int ax = dir == 0 ? -1 : (dir == 1 ? 1 : 0);
  const int ay = dir == 2 ? -1 : (dir == 3 ? 1 : 0);
  int cells[3];
  Vec2 shifts[3] = {};
  if (grid_.plain_neighbourhood(ix, iy)) {
    // Three cells in a row (step 1) or a column (step stride) of the table.
    const int step = ax != 0 ? grid_.stride() : 1;
    const int middle = grid_.index(ix + ax, iy + ay);
    cells[0] = middle - step;
    cells[1] = middle;
    cells[2] = middle + step;
  } else {
    for (int k = -1; k <= 1; ++k) {
      const auto nb = grid_.neighbour(ix, iy, ax != 0 ? ax : k, ay != 0 ? ay : k);
      cells[k + 1] = nb.cell;
      shifts[k + 1] = nb.shift;
    }
  }
  for (int k = 0; k < 3; ++k) {
    const int cell = cells[k];
    scan_cell(i, bi, cell, shifts[k], p);
    if (!grid_.has_walls(cell)) continue;
    for (auto it = grid_.walls_begin(cell); it != grid_.walls_end(cell); ++it) consider_wall(i, bi, *it, shifts[k], p);
    for (auto it = grid_.ends_begin(cell); it != grid_.ends_end(cell); ++it) consider_end(i, bi, *it, shifts[k], p);
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::predict_crossing(std::uint32_t i, int ix, int iy) {
  const Body& b = body_[i];
  Pending& p = pending_[i];
  // Relative to the cell's edges, computed from the cell index rather than re-derived from the
  // position, so a body sitting on an edge by round-off is never assigned twice.
  AxisExit ex, ey;
  if (is_turtle(i)) {
    ex = FreeFlight::exit(b.x.x, b.v.x, grid_.x_line(ix - 1), grid_.x_line(ix));
    ey = FreeFlight::exit(b.x.y, b.v.y, grid_.y_line(iy - 1), grid_.y_line(iy));
  } else {
    ex = flight_.exit_x(b.x.x, b.v.x, grid_.x_line(ix - 1), grid_.x_line(ix));
    ey = flight_.exit_y(b.x.y, b.v.y, grid_.y_line(iy - 1), grid_.y_line(iy));
  }
  if (ex.t <= ey.t) {
    p.t_cross = now_ + ex.t;
    p.cross_dir = ex.upper ? 1 : 0;
  } else {
    p.t_cross = now_ + ey.t;
    p.cross_dir = ey.upper ? 3 : 2;
  }
}

}  // namespace
}  // namespace turtlegas::sim::detail
