// SPDX-License-Identifier: MIT
#include "gas.hpp"

#include "turtlegas/sim/cover_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

namespace turtlegas::world::detail {
namespace {

using sim::Vec2;

/// Doubles from std::mt19937_64 by hand: std::uniform_real_distribution's output is
/// implementation-defined, and the gas must be the same on every platform.
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  /// Uniform in [0, 1), 53 random bits.
  double unit() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// Uniform integer in [0, n), n > 0.
  std::size_t below(std::size_t n) {
    return std::min(n - 1, static_cast<std::size_t>(unit() * static_cast<double>(n)));
  }
  /// A point uniform in the unit disc, away from its centre; rejection sampling needs no sin/cos,
  /// whose last bits differ between C libraries.
  Vec2 in_disc() {
    for (;;) {
      const Vec2 v{2.0 * unit() - 1.0, 2.0 * unit() - 1.0};
      const double s = sim::norm2(v);
      if (s <= 1.0 && s > 0x1.0p-40) return v;
    }
  }
  /// A vector of length `speed` (to a few ulps) in a uniformly random direction.
  Vec2 direction(double speed) {
    const Vec2 v = in_disc();
    const double k = speed / std::sqrt(sim::norm2(v));
    return {k * v.x, k * v.y};
  }

 private:
  std::mt19937_64 engine_;
};

/// Clips segment p-q to the box [lo, hi] (Liang-Barsky); false when nothing is left.
bool clip(Vec2& p, Vec2& q, Vec2 lo, Vec2 hi) {
  double t0 = 0.0, t1 = 1.0;
  const Vec2 d = q - p;
  auto edge = [&](double den, double num) {  // keeps the part where den * t <= num
    if (den == 0.0) return num >= 0.0;
    const double t = num / den;
    if (den < 0.0) t0 = std::max(t0, t);
    else t1 = std::min(t1, t);
    return t0 <= t1;
  };
  if (!edge(-d.x, p.x - lo.x) || !edge(d.x, hi.x - p.x) || !edge(-d.y, p.y - lo.y) || !edge(d.y, hi.y - p.y))
    return false;
  const Vec2 a = p + t0 * d, b = p + t1 * d;
  p = a;
  q = b;
  return true;
}

/// Everything a new disc must not overlap, in a uniform grid of linked cell lists. Items are
/// `ball * 2` or `wall * 2 + 1`, where a "wall" index past the walls is a turtle (walls and turtles
/// do not change while a gas is placed, balls do); discs are entered in every cell their bounding box covers, walls in
/// every cell their (clipped) segment crosses, so an overlapping pair always shares a cell.
class ObstacleGrid {
 public:
  ObstacleGrid(Vec2 lo, Vec2 hi, double side, std::size_t max_cells) : lo_(lo), hi_(hi), grid_(lo, hi, side, max_cells) {}

  std::size_t cell_of(Vec2 c) const { return grid_.cell_of(c); }
  double cells_per_disc(double r) const { return grid_.cells_per_disc(r); }
  void reserve(std::size_t entries) { grid_.reserve(entries); }
  void release_lists() { grid_.release_lists(); }

  bool touches(Vec2 c, double r) const {
    return c.x + r >= lo_.x && c.x - r <= hi_.x && c.y + r >= lo_.y && c.y - r <= hi_.y;
  }
  void add_disc(Vec2 c, double r, std::uint32_t item) { grid_.insert(grid_.cover_disc(c, r), item); }
  void add_segment(Vec2 p, Vec2 q, std::uint32_t item) {
    if (clip(p, q, lo_, hi_)) grid_.insert_segment(p, q, item);
  }

  /// Whether a disc at c of radius r overlaps (not merely touches) anything in the grid.
  bool blocked(Vec2 c, double r, const sim::WorldDef& def) const {
    return grid_.any(grid_.cover_disc(c, r), [&](std::uint32_t item) {
      if (item % 2 == 0) {
        const sim::BallDef& b = def.balls[item / 2];
        const double s = r + b.radius;
        return sim::norm2(c - b.pos) < s * s;
      }
      if (item / 2 < def.walls.size()) {
        const sim::WallDef& w = def.walls[item / 2];
        return sim::segment_distance2(c, w.from, w.to) < r * r;
      }
      const sim::TurtleDef& t = def.turtles[item / 2 - def.walls.size()];
      const double s = r + t.radius;
      return sim::norm2(c - t.pos) < s * s;
    });
  }

 private:
  Vec2 lo_, hi_;
  sim::CoverGrid grid_;
};

/// The exact tests validate() applies, so that no rounding in lo + u (hi - lo) can put a disc a
/// hair outside the region or the arena.
bool inside(Vec2 c, const GasSpec& gas, const sim::ArenaDef& arena) {
  const double r = gas.radius;
  return c.x - r >= gas.lo.x && c.x + r <= gas.hi.x && c.y - r >= gas.lo.y && c.y + r <= gas.hi.y &&
         c.x - r >= 0.0 && c.x + r <= arena.width && c.y - r >= 0.0 && c.y + r <= arena.height;
}

sim::BallDef make_ball(const GasSpec& gas, std::size_t k, Vec2 pos, Vec2 vel) {
  sim::BallDef b;
  b.id = gas.id_prefix + std::to_string(k);
  b.pos = pos;
  b.vel = vel;
  b.radius = gas.radius;
  b.mass = gas.mass;
  b.charge = gas.charge;
  b.layers = gas.layers;
  return b;
}

/// Stable-sorts balls[first..] by the grid cell of their centres. Sorts (cell, index) pairs and
/// then moves each ball once along the permutation's cycles, rather than stable-sorting the
/// balls themselves, whose buffer would hold half of them again.
void sort_by_cell(std::vector<sim::BallDef>& balls, std::size_t first, const ObstacleGrid& grid) {
  struct Key {
    std::size_t cell;
    std::uint32_t index;
    bool operator<(const Key& o) const { return cell != o.cell ? cell < o.cell : index < o.index; }
  };
  const std::size_t n = balls.size() - first;
  std::vector<Key> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = {grid.cell_of(balls[first + k].pos), static_cast<std::uint32_t>(k)};
  std::sort(order.begin(), order.end());
  // Position k receives the ball now at order[k].index; a finished position is marked with its own index.
  for (std::size_t start = 0; start < n; ++start) {
    if (order[start].index == start) continue;
    sim::BallDef held = std::move(balls[first + start]);
    std::size_t k = start;
    while (order[k].index != start) {
      const std::size_t from = order[k].index;
      balls[first + k] = std::move(balls[first + from]);
      order[k].index = static_cast<std::uint32_t>(k);
      k = from;
    }
    balls[first + k] = std::move(held);
    order[k].index = static_cast<std::uint32_t>(k);
  }
}

/// Random sequential addition: uniform candidates, rejected when they overlap anything placed.
/// Gives up after a bounded number of candidates, which in practice only happens near jamming
/// (area fraction ~0.547) or when obstacles fill the region.
std::size_t place_random(sim::WorldDef& def, const GasSpec& gas, ObstacleGrid& grid, Vec2 lo, Vec2 hi,
                         Random& rng) {
  const std::size_t first = def.balls.size();
  const std::uint64_t budget = 100 * static_cast<std::uint64_t>(gas.count) + 100000;
  // 2% over the average, plus a little: a sum over many discs hardly strays from its mean.
  grid.reserve(static_cast<std::size_t>(1.02 * static_cast<double>(gas.count) * grid.cells_per_disc(gas.radius)) + 1024);
  std::size_t placed = 0;
  for (std::uint64_t attempt = 0; attempt < budget && placed < gas.count; ++attempt) {
    const double u = rng.unit(), v = rng.unit();
    const Vec2 c{std::min(hi.x, lo.x + u * (hi.x - lo.x)), std::min(hi.y, lo.y + v * (hi.y - lo.y))};
    if (!inside(c, gas, def.arena) || grid.blocked(c, gas.radius, def)) continue;
    def.balls.push_back(make_ball(gas, placed, c, rng.direction(gas.speed)));
    grid.add_disc(c, gas.radius, static_cast<std::uint32_t>((first + placed) * 2));
    ++placed;
  }
  // Candidates land in random order; sorted by cell, neighbours are close in memory, which makes
  // validation and the engine's first steps several times faster. Ids follow the sorted order.
  grid.release_lists();
  sort_by_cell(def.balls, first, grid);
  for (std::size_t k = 0; k < placed; ++k) def.balls[first + k].id = gas.id_prefix + std::to_string(k);
  return placed;
}

/// A dense gas: a hexagonal lattice as coarse as still gives `count` free sites, `count` sites
/// chosen at random, each ball jittered around its site by up to half the spare spacing (so
/// neighbours cannot overlap). Starts nearly crystalline; it melts within a few collision times.
std::size_t place_lattice(sim::WorldDef& def, const GasSpec& gas, const ObstacleGrid& grid, Vec2 lo, Vec2 hi,
                          Random& rng) {
  const double r = gas.radius;
  const double ex = hi.x - lo.x, ey = hi.y - lo.y;
  const double row = std::sqrt(3.0) / 2.0;
  // At the closest packing neighbours are a hair over 2r apart, so rounding in the site
  // coordinates cannot make them overlap.
  const double d_min = 2.0 * r * (1.0 + 1e-9);
  auto raw_sites = [&](double d) {
    const double cols = std::floor(ex / d) + 1.0, rows = std::floor(ey / (d * row)) + 1.0;
    return cols * rows;
  };
  auto free_sites = [&](double d, std::vector<Vec2>& out) {
    out.clear();
    const double h = d * row;
    const auto rows = static_cast<std::size_t>(std::floor(ey / h)) + 1;
    for (std::size_t j = 0; j < rows; ++j) {
      const double shift = j % 2 == 1 ? d / 2.0 : 0.0;
      const double y = lo.y + static_cast<double>(j) * h;
      for (std::size_t i = 0;; ++i) {
        const double x = lo.x + shift + static_cast<double>(i) * d;
        if (x > hi.x) break;
        const Vec2 c{x, y};
        if (inside(c, gas, def.arena) && !grid.blocked(c, r, def)) out.push_back(c);
      }
    }
  };

  const double count = static_cast<double>(gas.count);
  double d = std::max(d_min, std::sqrt(2.0 * (ex + 2.0 * r) * (ey + 2.0 * r) / (std::sqrt(3.0) * count)));
  while (d > d_min && raw_sites(d) < count) d = std::max(d_min, d * 0.99);
  std::vector<Vec2> sites;
  for (;;) {
    free_sites(d, sites);
    if (sites.size() >= gas.count || d <= d_min) break;
    d = std::max(d_min, d * 0.98);
  }

  const std::size_t n = std::min(gas.count, sites.size());
  for (std::size_t k = 0; k < n; ++k) std::swap(sites[k], sites[k + rng.below(sites.size() - k)]);
  sites.resize(n);
  // Row-major order keeps neighbours close in memory for the engine.
  std::sort(sites.begin(), sites.end(), [](Vec2 a, Vec2 b) { return a.y < b.y || (a.y == b.y && a.x < b.x); });

  const double jitter = (d - d_min) / 2.0;
  for (std::size_t k = 0; k < n; ++k) {
    Vec2 c = sites[k];
    if (jitter > 0.0) {
      const Vec2 j = sites[k] + jitter * rng.in_disc();
      if (inside(j, gas, def.arena) && !grid.blocked(j, r, def)) c = j;
    }
    def.balls.push_back(make_ball(gas, k, c, rng.direction(gas.speed)));
  }
  return n;
}

}  // namespace

void centre_range(const GasSpec& gas, const sim::ArenaDef& arena, Vec2& lo, Vec2& hi) {
  lo = {std::max(gas.lo.x, 0.0) + gas.radius, std::max(gas.lo.y, 0.0) + gas.radius};
  hi = {std::min(gas.hi.x, arena.width) - gas.radius, std::min(gas.hi.y, arena.height) - gas.radius};
}

void thermalise(sim::WorldDef& def, std::size_t first, const GasSpec& gas);

std::size_t place_gas(sim::WorldDef& def, const GasSpec& gas) {
  Vec2 lo, hi;
  centre_range(gas, def.arena, lo, hi);
  if (gas.count == 0 || lo.x > hi.x || lo.y > hi.y) return 0;

  const double r = gas.radius;
  const Vec2 glo = lo - Vec2{r, r}, ghi = hi + Vec2{r, r};
  const std::size_t others = def.balls.size() + def.walls.size() + def.turtles.size();
  ObstacleGrid grid(glo, ghi, 2.0 * r, 4 * (gas.count + others) + 4096);
  for (std::size_t i = 0; i < def.balls.size(); ++i) {
    const sim::BallDef& b = def.balls[i];
    if (grid.touches(b.pos, b.radius)) grid.add_disc(b.pos, b.radius, static_cast<std::uint32_t>(i * 2));
  }
  for (std::size_t w = 0; w < def.walls.size(); ++w)
    grid.add_segment(def.walls[w].from, def.walls[w].to, static_cast<std::uint32_t>(w * 2 + 1));
  for (std::size_t k = 0; k < def.turtles.size(); ++k) {
    const sim::TurtleDef& t = def.turtles[k];
    if (grid.touches(t.pos, t.radius))
      grid.add_disc(t.pos, t.radius, static_cast<std::uint32_t>((def.walls.size() + k) * 2 + 1));
  }

  Random rng(gas.seed);
  def.balls.reserve(def.balls.size() + gas.count);
  const std::size_t first = def.balls.size();
  const double fraction = static_cast<double>(gas.count) * std::numbers::pi * r * r / ((ghi.x - glo.x) * (ghi.y - glo.y));
  const std::size_t placed = fraction > lattice_fraction ? place_lattice(def, gas, grid, lo, hi, rng)
                                                         : place_random(def, gas, grid, lo, hi, rng);
  if (gas.temperature >= 0.0) thermalise(def, first, gas);
  return placed;
}

void thermalise(sim::WorldDef& def, std::size_t first, const GasSpec& gas) {
  const std::size_t n = def.balls.size() - first;
  if (n == 0) return;
  // A stream of its own, so that the positions stay those of the same seed at a fixed speed.
  Random rng(gas.seed ^ 0x9e3779b97f4a7c15ULL);
  // Marsaglia's polar method: two independent normals from a point uniform in the unit disc (no
  // sin/cos; std::log and std::sqrt only, so the velocities are bit-identical wherever the C
  // library's log is, as glibc's is correctly rounded in practice).
  Vec2 mean{};
  for (std::size_t i = first; i < def.balls.size(); ++i) {
    const Vec2 u = rng.in_disc();
    const double s = sim::norm2(u), k = std::sqrt(-2.0 * std::log(s) / s);
    def.balls[i].vel = {k * u.x, k * u.y};
    mean += def.balls[i].vel;
  }
  // Zero total momentum (one mass for the whole gas), then the kinetic energy made exactly
  // (n - 1) kT: kT = sum m |v|^2 / (2 (n - 1)), what a momentum-conserving run measures.
  mean = mean / static_cast<double>(n);
  double twice_ke = 0.0;
  for (std::size_t i = first; i < def.balls.size(); ++i) {
    def.balls[i].vel -= mean;
    twice_ke += gas.mass * sim::norm2(def.balls[i].vel);
  }
  const double scale = n > 1 && twice_ke > 0.0 ? std::sqrt(2.0 * static_cast<double>(n - 1) * gas.temperature / twice_ke) : 0.0;
  for (std::size_t i = first; i < def.balls.size(); ++i) def.balls[i].vel *= scale;
}

}  // namespace turtlegas::world::detail
