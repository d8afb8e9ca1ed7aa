// SPDX-License-Identifier: MIT
#pragma once

#include <compare>
#include <cstdint>
#include <vector>

#include "turtlegas/sim/toi.hpp"
#include "turtlegas/sim/vec2.hpp"

namespace turtlegas::sim::detail {

/// A wall end point, shared by every wall that ends there.
struct WallEnd {
  Vec2 p;
  std::uint32_t wall = 0;  ///< the first wall that owns it (named in events)
};

/// The memo's table: nx by ny cells over the arena plus a ring of perimeter cells, so
/// (nx+2) x (ny+2) in all. Cell (ix, iy), ix in [0, nx+1], covers
/// [(ix-1) w, ix w] x [(iy-1) h, iy h]; arena cells have ix in [1, nx]. Cells are squares of the
/// requested side when it divides the arena, otherwise stretched so a whole number fit.
/// Walls are listed in every cell they pass through, wall ends in the cell that holds them.
class CellGrid {
 public:
  /// What one grid may take, in bytes (docs/physics.md, "The grid"): the constructor refuses a
  /// grid whose cells and wall lists would take more, naming arena.cell and the longest wall.
  static constexpr double kMemoryBudget = 1e9;

  CellGrid() = default;
  /// Walls flagged in `skip` (moving walls, checked apart from the table) are not listed.
  CellGrid(double width, double height, double min_cell, bool periodic,
           const std::vector<Segment>& walls, const std::vector<WallEnd>& ends,
           const std::vector<bool>& skip = {});

  int nx() const { return nx_; }
  int ny() const { return ny_; }
  int stride() const { return nx_ + 2; }
  int cell_count() const { return (nx_ + 2) * (ny_ + 2); }
  double cell_w() const { return cw_; }
  double cell_h() const { return ch_; }
  double width() const { return width_; }
  double height() const { return height_; }
  bool periodic() const { return periodic_; }

  int index(int ix, int iy) const { return iy * stride() + ix; }
  int ix_of(int cell) const { return cell % stride(); }
  int iy_of(int cell) const { return cell / stride(); }
  /// The arena cell holding p (clamped into the arena cells).
  int arena_cell_of(Vec2 p) const;
  /// The grid line between columns k and k+1 (rows, for y_edge); exact at the arena's edges.
  double x_edge(int k) const { return k < nx_ ? k * cw_ : width_ + (k - nx_) * cw_; }
  double y_edge(int k) const { return k < ny_ ? k * ch_ : height_ + (k - ny_) * ch_; }
  /// x_edge(k) and y_edge(k) from a table, k in [0, nx+1] (resp. [0, ny+1]), for the hot paths.
  double x_line(int k) const { return x_lines_[static_cast<std::size_t>(k)]; }
  double y_line(int k) const { return y_lines_[static_cast<std::size_t>(k)]; }
  /// False when a cell lists no walls or ends and has none in its 3x3 neighbourhood (most cells).
  bool has_walls(int cell) const { return slot_[static_cast<std::size_t>(cell)] != 0; }

  /// Neighbour (ix+dx, iy+dy) of an arena cell, wrapped when periodic; `shift` is what to add to
  /// the positions of objects listed there to see them from the original cell.
  struct Neighbour {
    int cell;
    Vec2 shift;
  };
  Neighbour neighbour(int ix, int iy, int dx, int dy) const {
    int jx = ix + dx, jy = iy + dy;
    Vec2 shift{};
    if (periodic_) {
      if (jx < 1) { jx += nx_; shift.x = -width_; }
      else if (jx > nx_) { jx -= nx_; shift.x = width_; }
      if (jy < 1) { jy += ny_; shift.y = -height_; }
      else if (jy > ny_) { jy -= ny_; shift.y = height_; }
    }
    return {index(jx, jy), shift};
  }
  /// Whether every cell of the 3x3 neighbourhood of arena cell (ix, iy) is seen without a shift,
  /// so that neighbour (dx, dy) is simply index(ix, iy) + dy * stride() + dx.
  bool plain_neighbourhood(int ix, int iy) const {
    return !periodic_ || (ix > 1 && ix < nx_ && iy > 1 && iy < ny_);
  }

  /// Walls passing through a cell, and wall ends inside it.
  const std::uint32_t* walls_begin(int cell) const { return wall_items_.data() + ranges(cell).walls[0]; }
  const std::uint32_t* walls_end(int cell) const { return wall_items_.data() + ranges(cell).walls[1]; }
  const std::uint32_t* ends_begin(int cell) const { return end_items_.data() + ranges(cell).ends[0]; }
  const std::uint32_t* ends_end(int cell) const { return end_items_.data() + ranges(cell).ends[1]; }

  /// Walls and ends within the 3x3 neighbourhood of an arena cell, each listed once with the
  /// shift (index into shifts()) under which it is seen; built for exact mode's full rescans.
  struct Near {
    std::uint32_t item;
    std::uint32_t shift;
    friend auto operator<=>(const Near&, const Near&) = default;
  };
  const Near* near_walls_begin(int cell) const { return near_walls_.data() + ranges(cell).near_walls[0]; }
  const Near* near_walls_end(int cell) const { return near_walls_.data() + ranges(cell).near_walls[1]; }
  const Near* near_ends_begin(int cell) const { return near_ends_.data() + ranges(cell).near_ends[0]; }
  const Near* near_ends_end(int cell) const { return near_ends_.data() + ranges(cell).near_ends[1]; }
  /// Periodic arenas: what the ring cells list (walls and ends on the seam x = W or y = H, or
  /// reaching below x = 0 or y = 0), folded into the arena cell across the seam, each with the
  /// shift (index into shifts()) that brings it to the arena cell's side. Step mode's ring scans
  /// read these beside walls_begin/ends_begin, which never reach a ring cell in a periodic arena.
  const Near* seam_walls_begin(int cell) const { return seam_walls_.data() + ranges(cell).seam_walls[0]; }
  const Near* seam_walls_end(int cell) const { return seam_walls_.data() + ranges(cell).seam_walls[1]; }
  const Near* seam_ends_begin(int cell) const { return seam_ends_.data() + ranges(cell).seam_ends[0]; }
  const Near* seam_ends_end(int cell) const { return seam_ends_.data() + ranges(cell).seam_ends[1]; }
  Vec2 shift(std::uint32_t k) const { return shifts_[k]; }
  std::uint32_t shift_index(Vec2 s) const;

  std::size_t memory_bytes() const;

 private:
  int nx_ = 1, ny_ = 1;
  double cw_ = 1.0, ch_ = 1.0, width_ = 1.0, height_ = 1.0;
  bool periodic_ = false;
  // Most cells are far from every wall, so the lists are stored sparsely: each cell holds the
  // index of its record of ranges, and record 0 (all ranges empty) serves every cell without walls.
  // That keeps the table at 4 bytes per cell.
  struct Ranges {
    std::uint32_t walls[2] = {0, 0};
    std::uint32_t ends[2] = {0, 0};
    std::uint32_t near_walls[2] = {0, 0};
    std::uint32_t near_ends[2] = {0, 0};
    std::uint32_t seam_walls[2] = {0, 0};
    std::uint32_t seam_ends[2] = {0, 0};
  };
  const Ranges& ranges(int cell) const { return records_[slot_[static_cast<std::size_t>(cell)]]; }
  Ranges& record_for(std::uint32_t cell);
  template <class T>
  void store(std::vector<std::pair<std::uint32_t, T>>& pairs, std::vector<T>& items, std::uint32_t (Ranges::*range)[2]);

  std::vector<double> x_lines_, y_lines_;
  std::vector<std::uint32_t> slot_;
  std::vector<Ranges> records_;
  std::vector<std::uint32_t> wall_items_, end_items_;
  std::vector<Near> near_walls_, near_ends_, seam_walls_, seam_ends_;
  Vec2 shifts_[9];
};

}  // namespace turtlegas::sim::detail
