// SPDX-License-Identifier: MIT
// The 3-D overlap measure (World3::max_overlap_now): the deepest overlap of the scene now, relative
// to the smaller radius, in O(N) a measure. Independent of the engine's own cells (a self-check
// must not share what it checks); the tests' oracle is the every-pair loop of reference3d.hpp.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "turtlegas/sim/vec3.hpp"

namespace turtlegas::sim::detail {

/// The measure's buffers, kept between measures so that a run measuring at many instants
/// allocates once: the live spheres in bucket order (40 bytes each) and the buckets' ends.
struct Overlap3Scratch {
  struct Sphere {
    Vec3 at;
    double r = 0.0;
    std::uint32_t id = 0;
  };
  std::vector<Sphere> sphere;
  std::vector<std::uint32_t> end;
};

namespace overlap3 {

// floor(x / cell), clamped to +-2^62 in double first (a sphere far out, or a tiny radius, has an
// index past int64's range; neighbours of a clamped index stay in range).
inline std::int64_t cell_index(double x, double cell) {
  const double k = std::floor(x / cell);
  constexpr double kMax = 0x1p62;
  if (!(k > -kMax)) return -static_cast<std::int64_t>(kMax);
  if (!(k < kMax)) return static_cast<std::int64_t>(kMax);
  return static_cast<std::int64_t>(k);
}

/// Cubes of side at least `cell` hashed into 2^k buckets. Along a periodic axis (period > 0) a
/// whole number of cells tiles the period and indices wrap; elsewhere they are unbounded. Cells
/// that share a bucket only add pairs that are measured and found apart.
struct Cells {
  std::array<double, 3> side{}, period{};
  std::array<std::int64_t, 3> count{};
  std::uint64_t mask = 0;

  std::array<std::int64_t, 3> of(const Vec3& p) const {
    std::array<std::int64_t, 3> c{};
    for (int a = 0; a < 3; ++a) {
      if (period[a] > 0.0) {
        const double x = p[a] - period[a] * std::floor(p[a] / period[a]);
        c[a] = std::clamp<std::int64_t>(cell_index(x, side[a]), 0, count[a] - 1);
      } else {
        c[a] = cell_index(p[a], side[a]);
      }
    }
    return c;
  }
  std::uint32_t bucket(std::array<std::int64_t, 3> c) const {
    for (int a = 0; a < 3; ++a)
      if (period[a] > 0.0) c[a] = c[a] < 0 ? c[a] + count[a] : c[a] >= count[a] ? c[a] - count[a] : c[a];
    // Unsigned arithmetic wraps modulo 2^64, which the bucket count divides: a valid hash of any
    // index, the clamped +-2^62 too. Odd multipliers spread the three axes over the buckets.
    const std::uint64_t h = static_cast<std::uint64_t>(c[0]) * 0x9E3779B97F4A7C15ULL ^
                            static_cast<std::uint64_t>(c[1]) * 0xC2B2AE3D27D4EB4FULL ^
                            static_cast<std::uint64_t>(c[2]) * 0x165667B19E3779F9ULL;
    return static_cast<std::uint32_t>((h ^ (h >> 29)) & mask);
  }
};

}  // namespace overlap3

/// The deepest overlap among n spheres and between them and the walls, each relative to the
/// smaller radius involved; 0 when nothing overlaps. `pos(i)`, `radius(i)`, `alive(i)` read
/// sphere i (pos twice: it must give the same bits both times); `period[a]` > 0 makes axis a
/// periodic (minimum image); `wall_depth(i, x)` is the deepest relative overlap of sphere i at x
/// with any wall (the caller's walls, moving ones where they are now). O(N) for the pairs: the
/// spheres bucketed in cells of twice the largest radius, each met with the 27 cells around it.
template <class Pos, class Radius, class Alive, class WallDepth>
double deepest_overlap3(Overlap3Scratch& s, std::size_t n, Pos&& pos, Radius&& radius, Alive&& alive,
                        const std::array<double, 3>& period, WallDepth&& wall_depth) {
  double worst = 0.0;
  double rmax = 0.0;
  std::size_t live = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (alive(i)) rmax = std::max(rmax, radius(i)), ++live;
  if (live == 0 || !(rmax > 0.0)) return worst;
  overlap3::Cells c;
  const double cell = 2.0 * rmax;
  for (int a = 0; a < 3; ++a) {
    c.period[a] = period[a];
    c.side[a] = cell;
    if (period[a] > 0.0) {
      c.count[a] = std::clamp<std::int64_t>(overlap3::cell_index(period[a], cell), 1, std::int64_t{1} << 20);
      c.side[a] = period[a] / static_cast<double>(c.count[a]);
    }
  }
  const std::size_t buckets = std::bit_ceil(std::max<std::size_t>(live, 2));
  c.mask = buckets - 1;
  s.end.assign(buckets, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (alive(i)) ++s.end[c.bucket(c.of(pos(i)))];
  std::uint32_t sum = 0;
  for (std::uint32_t& e : s.end) {
    sum += e;
    e = sum - e;  // the bucket's start, for now; after the fill below, its end
  }
  s.sphere.resize(live);
  for (std::size_t i = 0; i < n; ++i) {
    if (!alive(i)) continue;
    const Vec3 p = pos(i);
    s.sphere[s.end[c.bucket(c.of(p))]++] = {p, radius(i), static_cast<std::uint32_t>(i)};
  }
  auto image = [&](Vec3 d) {
    for (int a = 0; a < 3; ++a)
      if (period[a] > 0.0) d[a] -= period[a] * std::nearbyint(d[a] / period[a]);
    return d;
  };
  for (const Overlap3Scratch::Sphere& x : s.sphere) {
    worst = std::max(worst, wall_depth(x.id, x.at));
    const std::array<std::int64_t, 3> home = c.of(x.at);
    for (std::int64_t dz = -1; dz <= 1; ++dz)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          const std::uint32_t b = c.bucket({home[0] + dx, home[1] + dy, home[2] + dz});
          const std::uint32_t from = b == 0 ? 0 : s.end[b - 1];
          for (std::uint32_t k = from; k < s.end[b]; ++k) {
            const Overlap3Scratch::Sphere& y = s.sphere[k];
            if (y.id <= x.id) continue;  // each pair once, from its lower id
            const double depth = x.r + y.r - norm(image(y.at - x.at));
            if (depth > 0.0) worst = std::max(worst, depth / std::min(x.r, y.r));
          }
        }
  }
  return worst;
}

}  // namespace turtlegas::sim::detail
