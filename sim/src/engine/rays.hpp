// SPDX-License-Identifier: MIT
// Ray casts (World::cast_ray): the grid walked along a ray, the memo's squares in the order the
// ray crosses them (a DDA over the cell lines, each line's distance computed afresh from the ray's
// origin, so nothing accumulates).
//
// What a cell must be searched for. A wall or a wall end the ray meets inside a cell is listed in
// that cell (walls in every cell they pass, ends in the cell that holds them); a disc it meets
// there has its centre at most one cell away (cells are at least a diameter wide; step mode adds
// the step's longest path since the lists were made, as region.hpp does: `pad` cells in all). So
// the walk searches the block of cells within `pad` of each cell it enters: the first block
// whole, then on each step only the strip the block gains on its leading side (a ray is monotone
// in x and in y, so no strip was searched before). Walls are searched in the strip too: a hit on a
// cell line found one cell late is still found. Once the best hit found is no farther than where
// the ray leaves the cell it is in, every object that could be nearer has been tested: it is the
// first hit. Ties go to the lower (target, index), so the answer does not depend on the order of
// the lists.
//
// Beyond the arena: in a periodic arena cell coordinates run on unbounded and wrap onto the arena's
// cells, the objects listed there seen shifted by whole periods (and the seam lists with their own
// shift, CellGrid::seam_walls_begin). In an open or walled arena the perimeter ring takes all that
// lies outside, so a cell beyond the arena reads the ring cell it clamps to; when the block clamps
// to the same cells in both axes for ever (the ray leaving the arena, or parallel to an axis out of
// it) the search is complete. Moving walls live outside the grid and are tested each at its pose now.
#pragma once

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace turtlegas::sim::detail {
namespace {

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
RayHit Engine<F, kBallBall, kStep, kExtras>::cast_ray(const Ray& ray) const {
  const Vec2 o = ray.origin;
  const double len = norm(ray.dir);
  if (!is_finite(o)) throw std::invalid_argument("cast_ray: the origin must be finite");
  if (!(len > 0.0) || !std::isfinite(len)) throw std::invalid_argument("cast_ray: the direction must be finite and not zero");
  if (!(ray.range >= 0.0)) throw std::invalid_argument("cast_ray: the range must be >= 0");
  const bool periodic = arena_.periodic();
  if (periodic && !std::isfinite(ray.range))
    throw std::invalid_argument("cast_ray: a ray in a periodic arena needs a finite range");
  const Vec2 u = ray.dir / len;
  const double range = ray.range;
  RayHit best;
  auto consider = [&](double d, RayTarget target, std::uint32_t index) {
    if (!(d <= range)) return;
    if (d < best.distance || (d == best.distance && (target < best.target || (target == best.target && index < best.index))))
      best = {d, target, index};
  };
  // Without extras every object has the default layers, and every wall is always there.
  const bool sees_default = ray.layers.collides_with(Layers{});
  auto sees_wall = [&](std::uint32_t w) {
    if constexpr (kExtras) return ray.layers.collides_with(walls_.layers[w]);
    else return sees_default;
  };
  auto sees_end = [&](std::uint32_t e) {
    if constexpr (kExtras) return ray.layers.collides_with(walls_.end_layers[e]);
    else return sees_default;
  };
  auto sees_body = [&](std::uint32_t i) {
    if constexpr (kExtras) return bodies_.layers.empty() ? sees_default : ray.layers.collides_with(bodies_.layers[i]);
    else return sees_default;
  };
  const std::uint32_t nb = bodies_.balls();
  auto test_bodies = [&](std::uint32_t head, Vec2 shift, RayTarget target) {
    for (std::uint32_t i = head; i != kNone; i = bodies_.body[i].next) {
      const Body& b = bodies_.body[i];
      const std::uint32_t index = target == RayTarget::ball ? i : i - nb;
      if (target == RayTarget::turtle && index == ray.self) continue;
      if (!sees_body(i)) continue;
      const Vec2 rel = motion_.pos(b, i, now_ - b.t) + shift - o;
      // Most discs listed near a ray pass wide of it: |rel x u| >= r is a miss (or a graze), and
      // ray_disc's other arithmetic is not needed. (An origin inside the disc has |rel x u| < r.)
      if (!(std::fabs(sim::cross(rel, u)) < b.r)) continue;
      consider(ray_disc(rel, u, b.r), target, index);
    }
  };
  auto test_wall = [&](std::uint32_t w, Vec2 shift) {
    if (!sees_wall(w)) return;
    Segment s = walls_.segments[w];
    s.p1 += shift;
    consider(ray_segment(o - s.p1, u, s), RayTarget::wall, w);
  };
  auto test_end = [&](std::uint32_t e, Vec2 shift) {
    if (!sees_end(e)) return;
    consider(ray_point(o - (walls_.ends[e].p + shift), u), RayTarget::wall_end, walls_.ends[e].wall);
  };

  const int nx = grid_.nx(), ny = grid_.ny();
  const double cw = grid_.cell_w(), ch = grid_.cell_h();
  int pad = 1;
  if constexpr (kStep) pad += static_cast<int>(std::ceil(step_.dmax / std::min(cw, ch)));
  auto floor_div = [](long long a, long long n) { return a >= 0 ? a / n : -((-a + n - 1) / n); };
  // Grid line k (between cells k and k + 1; cell k covers [line(k - 1), line(k)]) for any k.
  auto line = [&](long long k, int n, double period, double cell, bool x_axis) {
    if (periodic) {
      const long long q = floor_div(k, n);
      const int r = static_cast<int>(k - q * n);
      return static_cast<double>(q) * period + (x_axis ? grid_.x_line(r) : grid_.y_line(r));
    }
    if (k <= 0) return static_cast<double>(k) * cell;
    if (k >= n) return period + static_cast<double>(k - n) * cell;
    return x_axis ? grid_.x_line(static_cast<int>(k)) : grid_.y_line(static_cast<int>(k));
  };
  auto x_line = [&](long long k) { return line(k, nx, arena_.width, cw, true); };
  auto y_line = [&](long long k) { return line(k, ny, arena_.height, ch, false); };
  // The cell holding coordinate v: floor(v / cell) + 1, corrected against the lines themselves.
  auto cell_of = [&](double v, double cell, auto&& line_of) {
    const double f = std::clamp(std::floor(v / cell) + 1.0, -4.0e15, 4.0e15);
    auto k = static_cast<long long>(f);
    while (line_of(k - 1) > v) --k;
    while (line_of(k) <= v) ++k;
    return k;
  };
  // A cell (kx, ky) of the unbounded coordinates: the table's cell that lists its objects, and the
  // shift that brings them to where the ray sees them.
  // Inlined at its four call sites: out of line it took 20 % more time a ray (ray_bench).
  auto search = [&](long long kx, long long ky) __attribute__((always_inline)) {
    int ix, iy;
    Vec2 shift{};
    if (periodic) {
      const long long qx = floor_div(kx - 1, nx), qy = floor_div(ky - 1, ny);
      ix = static_cast<int>(kx - qx * nx);
      iy = static_cast<int>(ky - qy * ny);
      shift = {static_cast<double>(qx) * arena_.width, static_cast<double>(qy) * arena_.height};
    } else {
      ix = static_cast<int>(std::clamp<long long>(kx, 0, nx + 1));
      iy = static_cast<int>(std::clamp<long long>(ky, 0, ny + 1));
    }
    const int c = grid_.index(ix, iy);
    const auto cell = static_cast<std::size_t>(c);
    test_bodies(bodies_.head[cell], shift, RayTarget::ball);
    if constexpr (kExtras) test_bodies(bodies_.turtle_head[cell], shift, RayTarget::turtle);
    if (!grid_.has_walls(c)) return;
    for (const std::uint32_t* w = grid_.walls_begin(c); w != grid_.walls_end(c); ++w) test_wall(*w, shift);
    for (const std::uint32_t* e = grid_.ends_begin(c); e != grid_.ends_end(c); ++e) test_end(*e, shift);
    if (periodic) {
      for (auto* n = grid_.seam_walls_begin(c); n != grid_.seam_walls_end(c); ++n) test_wall(n->item, shift + grid_.shift(n->shift));
      for (auto* n = grid_.seam_ends_begin(c); n != grid_.seam_ends_end(c); ++n) test_end(n->item, shift + grid_.shift(n->shift));
    }
  };

  if constexpr (kExtras) {
    // Moving walls: not in the table; each at its pose now, its ends as points.
    for (const Mover& m : schedule_.movers) {
      const std::uint32_t w = m.wall;
      if (!sees_wall(w)) continue;
      const Segment s = m.segment_at(walls_.segments[w], now_);
      consider(ray_segment(o - s.p1, u, s), RayTarget::wall, w);
      consider(ray_point(o - s.p1, u), RayTarget::wall_end, w);
      consider(ray_point(o - (s.p1 + s.len * s.u), u), RayTarget::wall_end, w);
    }
  }

  long long kx = cell_of(o.x, cw, x_line), ky = cell_of(o.y, ch, y_line);
  for (long long jy = ky - pad; jy <= ky + pad; ++jy)
    for (long long jx = kx - pad; jx <= kx + pad; ++jx) search(jx, jy);
  const int sx = u.x > 0.0 ? 1 : (u.x < 0.0 ? -1 : 0), sy = u.y > 0.0 ? 1 : (u.y < 0.0 ? -1 : 0);
  // Distance to the next line the ray crosses in each axis (kNever along the other axis).
  auto next_x = [&] { return sx > 0 ? (x_line(kx) - o.x) / u.x : sx < 0 ? (x_line(kx - 1) - o.x) / u.x : kNever; };
  auto next_y = [&] { return sy > 0 ? (y_line(ky) - o.y) / u.y : sy < 0 ? (y_line(ky - 1) - o.y) / u.y : kNever; };
  // Open or walled arenas: an axis whose block clamps to the same ring cells from now on.
  auto frozen = [&](long long k, int s, int n) {
    return s == 0 || (s > 0 && k - pad >= n + 1) || (s < 0 && k + pad <= 0);
  };
  double tx = next_x(), ty = next_y();
  for (;;) {
    if (!periodic) {
      // A frozen axis is not stepped again: its block reads the same ring cells, all searched. (A
      // ray along x with sin(180 deg) = 1.2e-16 across it stepped x until that y crossing, 1e17
      // units on: a sensor of range 1e308 hung its program.)
      if (frozen(kx, sx, nx)) tx = kNever;
      if (frozen(ky, sy, ny)) ty = kNever;
    }
    const double leave = std::min(tx, ty);
    if (best.distance <= leave || leave > range) return best;
    if (!periodic && frozen(kx, sx, nx) && frozen(ky, sy, ny)) return best;
    if (tx <= ty) {
      kx += sx;
      tx = next_x();
      const long long jx = kx + sx * pad;
      for (long long jy = ky - pad; jy <= ky + pad; ++jy) search(jx, jy);
    } else {
      ky += sy;
      ty = next_y();
      const long long jy = ky + sy * pad;
      for (long long jx = kx - pad; jx <= kx + pad; ++jx) search(jx, jy);
    }
  }
}

// A sensor's rays at once (World::cast_rays). Whatever cast_ray finds for a ray lies in a cell of
// its walk or within `pad` cells of one, and every cell of the walk up to the range lies in the
// box of cells around [o - range, o + range] (one cell of slack for the floor's rounding, `pad`
// for the discs and the step). So the objects listed in that box, each tested with cast_ray's own
// closed forms, range test and tie rule, hold cast_ray's answer: the same distance, bit for bit,
// for every ray (a superset of the objects the walk tests cannot give a nearer hit, or the walk
// would have missed it). Each ray then costs its candidates, not a walk of the grid.
template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::cast_rays(const Ray& ray, const Vec2* dirs, std::size_t n, RayHit* out) const {
  const Vec2 o = ray.origin;
  const double range = ray.range;
  const double cw = grid_.cell_w(), ch = grid_.cell_h();
  int pad = 1;
  if constexpr (kStep) pad += static_cast<int>(std::ceil(step_.dmax / std::min(cw, ch)));
  const int nx = grid_.nx(), ny = grid_.ny();
  // The cell holding coordinate v (ring cells 0 and n + 1 take what lies beyond the arena), as
  // cast_ray's cell_of finds it: floor(v / cell) + 1, corrected against the lines themselves.
  auto cell_of = [&](double v, double cell, int cells, bool x_axis) {
    const auto line = [&](int k) { return x_axis ? grid_.x_line(k) : grid_.y_line(k); };
    int k = static_cast<int>(std::clamp(std::floor(v / cell) + 1.0, 0.0, cells + 1.0));
    while (k > 0 && line(k - 1) > v) --k;
    while (k <= cells && line(k) <= v) ++k;
    return k;
  };
  bool batch = !arena_.periodic() && is_finite(o) && std::isfinite(range) && range >= 0.0 && n > 1;
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;
  if (batch) {
    // The walk steps into a cell when its line is within range, a distance rounded once or twice:
    // the margin (far below a cell) takes in a cell whose line is that close to the box's edge.
    const double mx = range + 1e-9 * (range + std::fabs(o.x) + cw), my = range + 1e-9 * (range + std::fabs(o.y) + ch);
    x0 = std::max(0, cell_of(o.x - mx, cw, nx, true) - pad), x1 = std::min(nx + 1, cell_of(o.x + mx, cw, nx, true) + pad);
    y0 = std::max(0, cell_of(o.y - my, ch, ny, false) - pad), y1 = std::min(ny + 1, cell_of(o.y + my, ch, ny, false) + pad);
    // Each ray tests every candidate of the box, where a walk visits its first block and a strip
    // of 2 pad + 1 cells per cell crossed; a candidate's test costs less than a cell's visit, and
    // there are fewer discs than cells. So only while the box is at most 4 walks: a ring's short
    // rays gathered, a lidar's long rays (a box of thousands of cells) walked.
    const double walk = (2.0 * pad + 1.0) * (2.0 * pad + 1.0 + 2.0 * range / std::min(cw, ch));
    batch = static_cast<double>(x1 - x0 + 1) * (y1 - y0 + 1) <= 4.0 * walk;
  }
  if (!batch) {
    Ray r = ray;
    for (std::size_t k = 0; k < n; ++k) {
      r.dir = dirs[k];
      out[k] = cast_ray(r);
    }
    return;
  }
  for (std::size_t k = 0; k < n; ++k) {
    const double len = norm(dirs[k]);
    if (!(len > 0.0) || !std::isfinite(len)) throw std::invalid_argument("cast_ray: the direction must be finite and not zero");
  }
  const bool sees_default = ray.layers.collides_with(Layers{});
  struct Disc {
    Vec2 rel;
    double r;
    RayTarget target;
    std::uint32_t index;
  };
  // Scratch reused across calls on this thread (a World is read by one thread at a time).
  thread_local std::vector<Disc> discs;
  thread_local std::vector<std::uint32_t> walls, ends;
  discs.clear();
  walls.clear();
  ends.clear();
  const std::uint32_t nb = bodies_.balls();
  auto gather = [&](std::uint32_t head, RayTarget target) {
    for (std::uint32_t i = head; i != kNone; i = bodies_.body[i].next) {
      const Body& b = bodies_.body[i];
      const std::uint32_t index = target == RayTarget::ball ? i : i - nb;
      if (target == RayTarget::turtle && index == ray.self) continue;
      if constexpr (kExtras) {
        if (!(bodies_.layers.empty() ? sees_default : ray.layers.collides_with(bodies_.layers[i]))) continue;
      } else if (!sees_default) {
        continue;
      }
      // As cast_ray's rel (its shift is zero outside a periodic arena).
      discs.push_back({motion_.pos(b, i, now_ - b.t) + Vec2{} - o, b.r, target, index});
    }
  };
  for (int iy = y0; iy <= y1; ++iy)
    for (int ix = x0; ix <= x1; ++ix) {
      const int c = grid_.index(ix, iy);
      const auto cell = static_cast<std::size_t>(c);
      gather(bodies_.head[cell], RayTarget::ball);
      if constexpr (kExtras) gather(bodies_.turtle_head[cell], RayTarget::turtle);
      if (!grid_.has_walls(c)) continue;
      walls.insert(walls.end(), grid_.walls_begin(c), grid_.walls_end(c));
      ends.insert(ends.end(), grid_.ends_begin(c), grid_.ends_end(c));
    }
  // A wall passes through many cells: test it once.
  std::sort(walls.begin(), walls.end());
  walls.erase(std::unique(walls.begin(), walls.end()), walls.end());
  std::sort(ends.begin(), ends.end());
  ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
  auto seen = [&](const Layers& l) {
    if constexpr (kExtras) return ray.layers.collides_with(l);
    else return sees_default;
  };
  std::erase_if(walls, [&](std::uint32_t w) { return !seen(walls_.layers[w]); });
  std::erase_if(ends, [&](std::uint32_t e) { return !seen(walls_.end_layers[e]); });

  for (std::size_t k = 0; k < n; ++k) {
    const Vec2 u = dirs[k] / norm(dirs[k]);
    RayHit best;
    auto consider = [&](double d, RayTarget target, std::uint32_t index) {
      if (!(d <= range)) return;
      if (d < best.distance || (d == best.distance && (target < best.target || (target == best.target && index < best.index))))
        best = {d, target, index};
    };
    for (const Disc& d : discs) {
      if (!(std::fabs(sim::cross(d.rel, u)) < d.r)) continue;
      consider(ray_disc(d.rel, u, d.r), d.target, d.index);
    }
    for (const std::uint32_t w : walls) {
      Segment s = walls_.segments[w];
      s.p1 += Vec2{};
      consider(ray_segment(o - s.p1, u, s), RayTarget::wall, w);
    }
    for (const std::uint32_t e : ends) consider(ray_point(o - (walls_.ends[e].p + Vec2{}), u), RayTarget::wall_end, walls_.ends[e].wall);
    if constexpr (kExtras) {
      for (const Mover& m : schedule_.movers) {
        const std::uint32_t w = m.wall;
        if (!seen(walls_.layers[w])) continue;
        const Segment s = m.segment_at(walls_.segments[w], now_);
        consider(ray_segment(o - s.p1, u, s), RayTarget::wall, w);
        consider(ray_point(o - s.p1, u), RayTarget::wall_end, w);
        consider(ray_point(o - (s.p1 + s.len * s.u), u), RayTarget::wall_end, w);
      }
    }
    out[k] = best;
  }
}

}  // namespace
}  // namespace turtlegas::sim::detail
