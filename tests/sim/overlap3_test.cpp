// SPDX-License-Identifier: MIT
// The 3-D overlap measure (engine3d/overlap3.hpp, World3::max_overlap_now): its hashed grid finds
// the deepest overlap the every-pair loop finds, bit for bit, in open and periodic boxes, with
// radii of several sizes and coordinates far out; and World3 measures any N (it measured pairs only
// up to 4096 spheres, and `run --stats` reported 0 above that without measuring).
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "engine3d/overlap3.hpp"
#include "turtlegas/sim/gas3d.hpp"
#include "turtlegas/sim/world3d.hpp"

using namespace turtlegas::sim;

namespace {

struct Cloud {
  std::vector<Vec3> at;
  std::vector<double> r;
  std::vector<bool> alive;
};

Cloud cloud(std::mt19937_64& rng, std::size_t n, const std::array<double, 3>& box, double r_lo, double r_hi) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Cloud c;
  for (std::size_t i = 0; i < n; ++i) {
    c.at.push_back({box[0] * u(rng), box[1] * u(rng), box[2] * u(rng)});
    c.r.push_back(r_lo + (r_hi - r_lo) * u(rng));
    c.alive.push_back(u(rng) > 0.1);
  }
  return c;
}

double every_pair(const Cloud& c, const std::array<double, 3>& period) {
  double worst = 0.0;
  for (std::size_t i = 0; i < c.at.size(); ++i)
    for (std::size_t j = i + 1; j < c.at.size(); ++j) {
      if (!c.alive[i] || !c.alive[j]) continue;
      Vec3 d = c.at[j] - c.at[i];
      for (int a = 0; a < 3; ++a)
        if (period[a] > 0.0) d[a] -= period[a] * std::nearbyint(d[a] / period[a]);
      const double depth = c.r[i] + c.r[j] - norm(d);
      if (depth > 0.0) worst = std::max(worst, depth / std::min(c.r[i], c.r[j]));
    }
  return worst;
}

double gridded(detail::Overlap3Scratch& s, const Cloud& c, const std::array<double, 3>& period) {
  return detail::deepest_overlap3(
      s, c.at.size(), [&](std::size_t i) { return c.at[i]; }, [&](std::size_t i) { return c.r[i]; },
      [&](std::size_t i) { return c.alive[i]; }, period, [](std::uint32_t, const Vec3&) { return 0.0; });
}

}  // namespace

TEST_CASE("the 3-D overlap grid finds what every pair finds", "[overlap3]") {
  std::mt19937_64 rng(7);
  detail::Overlap3Scratch scratch;  // kept across measures, as a run keeps it
  int overlapping = 0;
  for (int trial = 0; trial < 60; ++trial) {
    INFO("trial " << trial);
    const bool periodic = trial % 2 == 1;
    const std::array<double, 3> box{10.0 + trial % 7, 12.0, 9.0 + trial % 3};
    const std::array<double, 3> period = periodic ? box : std::array<double, 3>{};
    // Sparse to dense, equal radii and radii from 0.05 to 1 (a large sphere among small ones
    // sets the cells: twice its radius).
    const double r_lo = trial % 3 == 0 ? 0.5 : 0.05;
    Cloud c = cloud(rng, 50 + 20 * static_cast<std::size_t>(trial % 10), box, r_lo, trial % 3 == 0 ? 0.5 : 1.0);
    if (trial % 4 >= 2) {
      // Sparse, with one shallow overlap planted: a pair 1e-3 of a radius into each other, its
      // centres almost a diameter apart, in any direction (the case a grid of too small cells
      // misses; the deep overlaps of a dense cloud have centres close together).
      c = cloud(rng, 20, box, 0.05, 0.2);
      std::uniform_real_distribution<double> u(0.0, 1.0);
      const Vec3 at{box[0] * u(rng), box[1] * u(rng), box[2] * u(rng)};
      const double z = 2.0 * u(rng) - 1.0, phi = 6.283185307179586 * u(rng), s = std::sqrt(1.0 - z * z);
      const double ra = 1.0, rb = 0.3 + 0.7 * u(rng);
      c.at.push_back(at);
      c.at.push_back(at + (ra + rb - 1e-3 * rb) * Vec3{s * std::cos(phi), s * std::sin(phi), z});
      c.r.insert(c.r.end(), {ra, rb});
      c.alive.insert(c.alive.end(), {true, true});
    }
    const double want = every_pair(c, period);
    CHECK(gridded(scratch, c, period) == want);
    overlapping += want > 0.0;
  }
  CHECK(overlapping > 50);  // the clouds do overlap: the comparison is not of zeros
}

TEST_CASE("the 3-D overlap grid across a periodic seam and far from the origin", "[overlap3]") {
  detail::Overlap3Scratch s;
  const std::array<double, 3> period{20.0, 20.0, 20.0};
  // Two spheres overlapping by 0.1 through the x seam only.
  Cloud seam{{{0.05, 5, 5}, {19.95 - 1.8, 5, 5}, {10, 10, 10}}, {1.0, 1.0, 0.5}, {true, true, true}};
  CHECK(gridded(s, seam, period) == Approx(0.1).epsilon(1e-12));
  CHECK(gridded(s, seam, {}) == 0.0);  // not periodic: 18.1 apart
  // Coordinates past int64's cells (radius 1e-22 at 1e6): clamped indices, no undefined behaviour.
  Cloud far{{{1e6, 0, 0}, {1e6 + 1e-22, 0, 0}, {-1e300, 1e300, 0}}, {1e-22, 1e-22, 1e-22}, {true, true, true}};
  CHECK(gridded(s, far, {}) == every_pair(far, {}));
}

TEST_CASE("World3 measures overlaps at any N", "[overlap3]") {
  // 4 x 13^3 = 8788 spheres of diameter 1 from the lattice, 2.5 apart.
  World3Def def = fcc_gas3(13, 0.05, 1);
  {
    World3 w(def);
    REQUIRE(w.sphere_count() > 4096);
    CHECK(w.max_overlap_now() == 0.0);
    w.advance_to(0.5);
    CHECK(w.max_overlap_now() <= 1e-9);
  }
  // Two spheres past the 4096th put 2e-13 into each other, which the definition's check lets pass
  // as round-off (1e-12 of the radii's sum): the measure sees 4e-13 of a radius (the old one
  // measured pairs only up to 4096 spheres and said 0).
  const std::size_t a = 5000, b = 5001;
  def.spheres[b].pos = def.spheres[a].pos + Vec3{1.0 - 2e-13, 0.0, 0.0};
  REQUIRE(check_world3(def).empty());
  World3 w(def);
  CHECK(w.max_overlap_now() == Approx(4e-13).epsilon(0.05));
}
