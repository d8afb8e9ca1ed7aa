// SPDX-License-Identifier: MIT
// A uniform magnetic field in 3-D (docs/physics.md, "3-D: magnetic fields"): the helix against its
// closed form (cyclotron period and radius, the turning sense, E x B drift), a helix meeting a plane
// at its closed-form times, and a box of charged spheres in B whose energy stays put over many
// bounces with no overlap.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

#include "reference3d.hpp"
#include "turtlegas/sim/gas3d.hpp"
#include "turtlegas/sim/toi3.hpp"
#include "turtlegas/sim/world3d.hpp"

using namespace turtlegas::sim;

namespace {

constexpr double kPi = 3.141592653589793;

World3Def open_arena() {
  World3Def def;
  def.size = {100, 100, 100};
  def.cell = 10;  // few cells: the default (a diameter) would be 500^3 of them here
  return def;
}

}  // namespace

TEST_CASE("cyclotron motion: radius m v / (q B), period 2 pi m / (q B), clockwise about B for q > 0") {
  // q = 2, m = 0.5, B = 0.75 along z: omega = 3. Starting at (50, 50, 50) at (v, 0, w) the guiding
  // centre is (50, 50 - v / omega, .), and x(t) = centre + (v / omega) (sin 3t, cos 3t) + w t z.
  const double v = 1.5, wz = 0.2, om = 3.0, rho = v / om;
  World3Def def = open_arena();
  def.magnetic = {0, 0, 0.75};
  def.spheres.push_back({{50, 50, 50}, {v, 0, wz}, 0.1, 0.5, 2.0});
  World3 w(def);
  for (int k = 1; k <= 40; ++k) {
    const double t = 0.37 * k;
    w.advance_to(t);
    INFO("t = " << t);
    CHECK(w.position(0).x == Approx(50 + rho * std::sin(om * t)).margin(1e-12));
    CHECK(w.position(0).y == Approx(50 - rho + rho * std::cos(om * t)).margin(1e-12));
    CHECK(w.position(0).z == Approx(50 + wz * t).margin(1e-12));
    CHECK(w.velocity(0).x == Approx(v * std::cos(om * t)).margin(1e-12));
    CHECK(w.velocity(0).y == Approx(-v * std::sin(om * t)).margin(1e-12));
  }
  // A quarter turn: moving +x it has turned to -y (clockwise seen from +z).
  World3 q(def);
  q.advance_to(kPi / (2 * om));
  CHECK(q.velocity(0).x == Approx(0.0).margin(1e-14));
  CHECK(q.velocity(0).y == Approx(-v).margin(1e-14));
  // B along any direction: the same motion, rotated. A full period brings the circle back.
  World3Def tilted = open_arena();
  const Vec3 b{0.48, 0.6, 0.64};  // unit
  tilted.magnetic = 0.75 * b;
  const Vec3 vperp = cross(b, Vec3{1, 0, 0});
  const Vec3 v0 = (v / norm(vperp)) * vperp + wz * b;
  tilted.spheres.push_back({{50, 50, 50}, v0, 0.1, 0.5, 2.0});
  World3 t(tilted);
  t.advance_to(2 * kPi / om);
  const Vec3 back = Vec3{50, 50, 50} + (wz * 2 * kPi / om) * b;
  CHECK(norm(t.position(0) - back) < 1e-12);
  CHECK(norm(t.velocity(0) - v0) < 1e-13);
  World3 h(tilted);
  h.advance_to(kPi / om);  // half a turn: the far side of the circle, 2 rho from the start across B
  const Vec3 across = h.position(0) - Vec3{50, 50, 50} - (wz * kPi / om) * b;
  CHECK(norm(across) == Approx(2 * rho).margin(1e-12));
}

TEST_CASE("E x B: a sphere at the drift velocity E x B / B^2 flies straight; otherwise it circles about it") {
  World3Def def = open_arena();
  def.magnetic = {0, 0, 2.0};
  def.electric = {0, 3.0, 0};
  def.gravity = {0, 0, -0.5};  // along B: a parabola along z, whatever the charge
  def.spheres.push_back({{20, 50, 80}, {1.5, 0, 0}, 0.1, 1.0, 1.0});   // at E x B / B^2 = (1.5, 0, 0)
  def.spheres.push_back({{20, 20, 80}, {1.5, 0.8, 0}, 0.1, 1.0, 1.0});  // circling at 0.8 about the drift
  World3 w(def);
  w.advance_to(10.0);
  CHECK(norm(w.position(0) - Vec3{35, 50, 80 - 0.25 * 100}) < 1e-12);
  CHECK(norm(w.velocity(0) - Vec3{1.5, 0, -5}) < 1e-13);
  // The second: omega = 2, u0 = (0, 0.8, 0); after a whole number of turns it is back on the drift.
  World3 p(def);
  p.advance_to(3 * kPi);  // three turns
  CHECK(norm(p.position(1) - Vec3{20 + 1.5 * 3 * kPi, 20, 80 - 0.25 * 9 * kPi * kPi}) < 1e-11);
}

TEST_CASE("a helix meets a plane at its closed-form times: the circle's arcsine and the drift's line") {
  // omega = 1 (q = m = 1, B = z), from (50, 50, 50) at (2, 0, -0.5): centre (50, 48), radius 2,
  // x = 50 + 2 sin t. A wall x = 51 + r (r = 0.5) is met where 2 sin t = 1 + 0.5... choose the
  // plane x = 51.5 + 0.5 = 52 - 0.5: sin t = 0.5, t = pi / 6. The floor z = 40 is met where
  // 50 - 0.5 t = 40 + r, t = 19.
  World3Def def = open_arena();
  def.magnetic = {0, 0, 1.0};
  def.spheres.push_back({{50, 50, 50}, {2, 0, -0.5}, 0.5, 1.0, 1.0});
  def.walls.push_back({{{51.5, 40, 30}, {51.5, 60, 30}, {51.5, 60, 60}, {51.5, 40, 60}}});
  World3 w(def);
  std::vector<Event3> log;
  w.advance_to(kPi / 6 + 1e-3, &log);
  REQUIRE(log.size() == 1);
  CHECK(log[0].kind == Event3Kind::ball_wall);
  CHECK(log[0].t == Approx(kPi / 6).margin(1e-11));  // found within the contact tolerance: 1e-12 r + 2^-44 of the arena
  // Reflected about x: the velocity (2 cos t, -2 sin t) = (sqrt 3, -1) became (-sqrt 3, -1).
  w.advance_to(kPi / 6);
  CHECK(w.max_overlap_now() <= 1e-9);

  World3Def floor = open_arena();
  floor.magnetic = {0, 0, 1.0};
  floor.spheres.push_back({{50, 50, 50}, {2, 0, -0.5}, 0.5, 1.0, 1.0});
  floor.walls.push_back({{{40, 40, 40}, {60, 40, 40}, {60, 60, 40}, {40, 60, 40}}});
  World3 f(floor);
  log.clear();
  f.advance_to(20.0, &log);
  REQUIRE(!log.empty());
  CHECK(log[0].kind == Event3Kind::ball_wall);
  CHECK(log[0].t == Approx(19.0).margin(1e-11));
  CHECK(f.velocity(0).z == Approx(0.5).margin(1e-12));
  CHECK(std::hypot(f.velocity(0).x, f.velocity(0).y) == Approx(2.0).margin(1e-12));
}

TEST_CASE("charged spheres in B in a closed box with a tilted polygon: energy kept to 1e-12, no overlap") {
  World3Def def;
  def.size = {20, 20, 20};
  def.boundary = Boundary3::walls;
  def.magnetic = {0.3, 0.5, 0.8};
  def.walls.push_back({{{4, 4, 8}, {15, 5, 10}, {7, 15, 9}}});
  std::mt19937_64 gen(11);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  while (def.spheres.size() < 60) {
    const Vec3 x{1 + 18 * uni(gen), 1 + 18 * uni(gen), 1 + 18 * uni(gen)};
    bool clear = distance_to_polygon(x, def.walls[0].corners) > 0.6;
    for (const Sphere3Def& s : def.spheres) clear = clear && norm(s.pos - x) > 1.2;
    if (!clear) continue;
    const double q = def.spheres.size() % 3 == 0 ? 0.0 : 4 * uni(gen) - 2;  // some uncharged
    def.spheres.push_back({x, {4 * uni(gen) - 2, 4 * uni(gen) - 2, 4 * uni(gen) - 2}, 0.5, 0.5 + uni(gen), q});
  }
  World3 w(def);
  const double e0 = w.energy();
  std::vector<Event3> log;
  w.advance_to(100.0, &log);
  int kinds[6] = {};
  for (const Event3& e : log) ++kinds[static_cast<int>(e.kind)];
  INFO("pairs " << kinds[0] << " faces " << kinds[1] << " edges " << kinds[2] << " corners " << kinds[3]);
  CHECK(kinds[0] > 150);  // 225 pairs, 953 faces, 23 edges, 1 corner
  CHECK(kinds[1] > 600);
  CHECK(kinds[2] >= 5);
  // 1197 collisions in 100 s: energy off by 2.4e-16 of itself, no overlap, contacts within 3.2e-12 r.
  CHECK(std::abs(w.energy() - e0) <= 1e-12 * e0);
  CHECK(w.max_overlap_now() <= 1e-9);
  CHECK(w.max_contact_error() <= 1e-9);
  for (std::size_t i = 0; i < w.sphere_count(); ++i) CHECK(w.alive(i));
}

TEST_CASE("helices: the engine agrees event for event with the brute-force reference") {
  // reference3d.hpp's scenes (8 spheres, a closed box of polygons, a slanted triangle and quad)
  // with random charges in B = (0.6, -0.9, 1.2), alone, with gravity, with E, and with the
  // triangle and the quad translating through keys (world3d_moving_test's): the reference steps
  // by conservative advancement on the distances with the helices' |x''|, finding contacts within
  // 1e-12 r; the engine by first_touch within 1e-10 r.
  int kinds[6] = {};
  for (std::uint64_t seed : {1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u}) {
    for (int field = 0; field < 4; ++field) {
      INFO("seed " << seed << " field " << field);
      World3Def def = turtlegas::test3::random_scene(seed, 8, field == 1, field == 2, true);
      if (field == 3) {
        def.walls[6].keys = {{2.0, {1.0, 0.5, -0.5}}, {5.0, {-0.5, 1.0, 1.0}}, {9.0, {0.0, 0.0, 0.0}}};
        def.walls[7].keys = {{3.0, {-1.0, -1.0, -1.0}}, {7.0, {-2.0, 0.0, -2.0}}, {12.0, {0.5, 0.5, 0.5}}};
      }
      const auto agreed = turtlegas::test3::agree_with_reference(def, 15.0, kinds);
      CHECK(agreed.overlap <= 1e-9);
    }
  }
  // 32 scenes: 1258 events (112 pairs, 1079 faces, 54 edges, 13 corners).
  INFO("pairs " << kinds[0] << " faces " << kinds[1] << " edges " << kinds[2] << " corners " << kinds[3]);
  CHECK(kinds[0] > 30);
  CHECK(kinds[2] >= 3);
  CHECK(kinds[3] >= 1);
}

TEST_CASE("a periodic gas of charged spheres in B: energy kept, no overlap, pairs across the boundary") {
  // The fcc start of the equation-of-state test (108 spheres, eta = 0.2), charges +-1 in
  // alternation, B = (0.4, -1.1, 0.7): radii m v / (q B) about the diameter, so every kind of
  // search (pair of helices, helix and straight) and wrapped images are exercised.
  World3Def def = fcc_gas3(3, 0.2, 9);
  def.magnetic = {0.4, -1.1, 0.7};
  for (std::size_t i = 0; i < def.spheres.size(); ++i) def.spheres[i].charge = i % 3 == 0 ? 0.0 : (i % 3 == 1 ? 1.0 : -1.0);
  World3 w(def);
  const double e0 = w.energy();
  w.advance_to(100.0);
  // 25748 collisions, 55492 events: energy off by 6.2e-14 of itself, contacts within 1.8e-12 r.
  INFO("collisions " << w.collisions() << ", drift " << std::abs(w.energy() - e0) / e0);
  CHECK(w.collisions() > 20000);
  CHECK(std::abs(w.energy() - e0) <= 1e-12 * e0);
  CHECK(w.max_overlap_now() <= 1e-9);
  CHECK(w.max_contact_error() <= 1e-9);
}

TEST_CASE("step mode with a magnetic field is refused") {
  World3Def def = open_arena();
  def.magnetic = {0, 0, 1};
  def.mode = Mode::step;
  CHECK(check_world3(def).find("exact mode only") != std::string::npos);
}
