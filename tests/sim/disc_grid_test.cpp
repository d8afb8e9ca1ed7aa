// SPDX-License-Identifier: MIT
// DiscGrid (sim/src/disc_grid.hpp), the scene checks' hashed cells: it finds every overlapping
// pair, and the work it does is set by the discs, not by the arena they are in.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "disc_grid.hpp"

using namespace turtlegas::sim;

namespace {

struct Disc {
  Vec2 c;
  double r;
};

/// Every pair (i < j) that overlaps, as near() from each disc sees them, and the items it visits.
std::uint64_t pairs_seen(const std::vector<Disc>& d, double side, std::vector<std::vector<bool>>* seen) {
  DiscGrid g(side);
  for (std::size_t i = 0; i < d.size(); ++i) g.add(d[i].c, d[i].r, static_cast<std::uint32_t>(i));
  g.build();
  std::uint64_t visits = 0;
  for (std::size_t i = 0; i < d.size(); ++i)
    g.near(d[i].c, d[i].r, [&](std::uint32_t j) {
      ++visits;
      const double s = d[i].r + d[j].r;
      if (seen && j != i && norm2(d[i].c - d[j].c) < s * s) (*seen)[std::min<std::size_t>(i, j)][std::max<std::size_t>(i, j)] = true;
      return false;
    });
  return visits;
}

}  // namespace

TEST_CASE("DiscGrid: every overlapping pair is seen from one side, radii over six orders", "[disc_grid]") {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    INFO("seed " << seed);
    std::mt19937_64 rng(seed);
    auto unit = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
    std::vector<Disc> d;
    for (int i = 0; i < 300; ++i) {
      const double r = 0.01 * std::pow(10.0, 6.0 * unit() * unit() * unit());  // mostly small, a few huge
      d.push_back({{unit() * 1000 - 500, unit() * 1000 - 500}, r});
    }
    std::vector<std::vector<bool>> seen(d.size(), std::vector<bool>(d.size(), false));
    pairs_seen(d, 0.04, &seen);
    for (std::size_t i = 0; i < d.size(); ++i)
      for (std::size_t j = i + 1; j < d.size(); ++j) {
        const double s = d[i].r + d[j].r;
        if (norm2(d[i].c - d[j].c) < s * s) {
          INFO("pair " << i << ", " << j);
          CHECK(seen[i][j]);
        }
      }
  }
}

TEST_CASE("DiscGrid: discs clustered in a 1e9 arena cost a few visits each, wherever the clusters are", "[disc_grid]") {
  // Two clusters of 10,000 touching discs, 1e9 apart: a grid laid over their extent (or over the
  // arena) puts each cluster in a cell or two and visits ~N^2 / 2 = 5e7 items; the hashed cells
  // visit a handful per disc.
  std::vector<Disc> d;
  for (const Vec2 corner : {Vec2{0, 0}, Vec2{1e9, 1e9}})
    for (int i = 0; i < 10000; ++i) d.push_back({corner + Vec2{2.0 * (i % 100), 2.0 * (i / 100)}, 1.0});
  const std::uint64_t visits = pairs_seen(d, 4.0, nullptr);
  INFO("visits " << visits);
  CHECK(visits <= 50 * d.size());  // about 20: 2.25 cells of about 9 entries
  CHECK(visits >= d.size());  // each disc sees itself at least
}
