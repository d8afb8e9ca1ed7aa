// SPDX-License-Identifier: MIT
#include "cell_size.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace turtlegas::sim::detail {

double choose_cell_size(const WorldDef& def, Mode mode) {
  const bool step = mode == Mode::step;
  const double width = def.arena.width, height = def.arena.height;
  double rmax = 0.0, vmax = 0.0;
  for (const auto& b : def.balls) {
    rmax = std::max(rmax, b.radius);
    vmax = std::max(vmax, norm(b.vel));
  }
  for (const auto& t : def.turtles) {
    rmax = std::max(rmax, t.radius);
    vmax = std::max(vmax, t.speed);
  }
  const std::size_t n = def.balls.size() + def.turtles.size();
  const double area = width * height;
  const double rule = step ? 2.0 * (rmax + vmax * def.dt) : 2.0 * rmax;
  if (def.arena.cell) {
    const double cell = *def.arena.cell;
    if (cell < rule) {
      const std::string why = step
          ? "the memo's rule in step mode needs cells wider than twice (largest radius + largest speed x dt) = " +
                std::to_string(rule) + "; set arena.cell >= that, use a smaller dt, or use --mode exact"
          : "exact mode needs cells at least as wide as the largest ball or turtle (diameter " + std::to_string(rule) +
                "); set arena.cell >= that";
      throw std::invalid_argument("arena.cell " + std::to_string(cell) + " is too small: " + why);
    }
    return cell;
  }
  double preferred = 0.0;
  if (!step && !def.effects.ball_ball && def.turtles.empty()) {
    // Exact mode, balls meeting walls only: their number says nothing about how fine the table
    // must be, and every cell crossing is an event that finds no partner. (Step mode has no
    // crossing events; there finer cells keep the walls out of most balls' neighbourhoods, so it
    // keeps the rule below.) So size the cells by the walls instead, at about one wall passing
    // through a cell: with total wall length L, L / cell cells are crossed by walls out of
    // area / cell^2, which is one each at cell = area / L. At most a quarter of the arena (a
    // plain box gets a 4 x 4 table); no walls at all (exits only) gives that too. Moving walls are
    // not in the table and do not count.
    double length = 0.0;
    auto add = [&](const WallDef& w) {
      if (w.keys.empty()) length += norm(w.to - w.from);
    };
    for (const WallDef& w : def.walls) add(w);
    if (def.arena.boundary == Boundary::walls)
      for (const WallDef& w : arena_walls(def.arena)) add(w);
    const double quarter = std::max(width, height) / 4.0;
    preferred = length > 0.0 ? std::min(area / length, quarter) : quarter;
  } else {
    // About 0.3 balls per cell: measured fastest in exact mode from area fraction 0.05 to 0.3
    // (fewer balls per cell means fewer candidates per prediction but more cell crossings).
    preferred = n > 0 ? std::sqrt(0.3 * area / static_cast<double>(n)) : std::max(width, height) / 16.0;
  }
  double cell = std::max(rule * (1.0 + 1e-9), preferred);
  cell = std::max(cell, std::sqrt(area / 4.0e7));  // keep the table under ~4e7 cells
  // Keep the walls' lists under ~1e7 entries: a wall is listed in each cell it crosses (about
  // length / cell + 2 of them) and again in the 3x3 neighbourhood of each, ten entries a cell.
  // (A 1e15-long arena wall once crossed 3e7 cells and took 10 GB.) Never binding for walls of a
  // sensible length: 4 x 1600 units of arena walls would need cells of 0.006.
  // Only the part of a wall inside the arena crosses cells (beyond it a ring cell takes it all).
  auto inside_length = [&](Vec2 p, Vec2 q) {
    double t0 = 0.0, t1 = 1.0;
    const Vec2 d = q - p;
    const double pk[4] = {-d.x, d.x, -d.y, d.y}, qk[4] = {p.x, width - p.x, p.y, height - p.y};
    for (int k = 0; k < 4; ++k) {
      if (pk[k] == 0.0) {
        if (qk[k] < 0.0) return 0.0;
      } else {
        const double r = qk[k] / pk[k];
        if (pk[k] < 0.0) t0 = std::max(t0, r);
        else t1 = std::min(t1, r);
      }
    }
    return t1 > t0 ? (t1 - t0) * norm(d) : 0.0;
  };
  double wall_length = 0.0;
  for (const WallDef& w : def.walls) wall_length += inside_length(w.from, w.to);
  if (def.arena.boundary == Boundary::walls) wall_length += 2.0 * (width + height);
  cell = std::max(cell, 10.0 * wall_length / 1.0e7);
  // A periodic arena needs three cells across, so that no pair is seen through two images.
  if (def.arena.boundary == Boundary::periodic)
    cell = std::max(rule * (1.0 + 1e-9), std::min(cell, std::min(width, height) / 3.0));
  return cell;
}

}  // namespace turtlegas::sim::detail
