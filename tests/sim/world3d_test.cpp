// SPDX-License-Identifier: MIT
// The 3-D room (docs/physics.md, "3-D"): closed-form single contacts of each kind, conservation,
// and agreement event for event with the independent reference of reference3d.hpp.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "reference3d.hpp"
#include "turtlegas/sim/toi3.hpp"
#include "turtlegas/sim/world3d.hpp"

using namespace turtlegas::sim;
using turtlegas::test3::random_scene;

namespace {

World3Def one_sphere(Vec3 pos, Vec3 vel, double r, std::vector<Vec3> corners) {
  World3Def def;
  def.size = {20, 20, 20};
  def.spheres.push_back({pos, vel, r, 1.0, 0.0});
  def.walls.push_back({corners});
  return def;
}

}  // namespace

TEST_CASE("a sphere onto a face: t = (height - r) / speed, velocity mirrored") {
  World3Def def = one_sphere({5, 5, 7}, {0.5, 0, -2}, 1.0, {{2, 2, 1}, {8, 2, 1}, {8, 8, 1}, {2, 8, 1}});
  World3 w(def);
  std::vector<Event3> log;
  w.advance_to(3.0, &log);
  REQUIRE(log.size() == 1);
  CHECK(log[0].kind == Event3Kind::ball_wall);
  CHECK(log[0].t == Approx(2.5).epsilon(1e-14));  // (7 - 1 - 1) / 2
  CHECK(w.velocity(0).z == Approx(2.0));
  CHECK(w.velocity(0).x == Approx(0.5));
}

TEST_CASE("a sphere onto an edge: the cylinder root t = 2, normal from the edge's nearest point") {
  // Triangle on z = 0 with y <= 0; the sphere comes down across the edge y = 0 from y > 0:
  // (3 - t)^2 + (2 - t)^2 = 1 at t = 2 (the face's plane root t = 1 falls outside the triangle).
  World3Def def = one_sphere({5, 13, 12}, {0, -1, -1}, 1.0, {{0, 10, 10}, {10, 10, 10}, {5, 0, 10}});
  World3 w(def);
  std::vector<Event3> log;
  w.advance_to(2.5, &log);
  REQUIRE(log.size() == 1);
  CHECK(log[0].kind == Event3Kind::ball_wall_edge);
  CHECK(log[0].c == 0);
  CHECK(log[0].t == Approx(2.0).epsilon(1e-13));
  CHECK(w.velocity(0).y == Approx(1.0));
  CHECK(w.velocity(0).z == Approx(-1.0));
}

TEST_CASE("a sphere onto a corner: the memo's wall-end formula, head-on reversal") {
  // Corner at (5, 5, 5), the sphere 1 above its plane on the outward diagonal: 2 (t - 2)^2 + 1 = 2.25.
  World3Def def = one_sphere({3, 3, 6}, {1, 1, 0}, 1.5, {{5, 5, 5}, {15, 5, 5}, {5, 15, 5}});
  World3 w(def);
  std::vector<Event3> log;
  w.advance_to(2.0, &log);
  REQUIRE(log.size() == 1);
  CHECK(log[0].kind == Event3Kind::ball_wall_corner);
  CHECK(log[0].c == 0);
  CHECK(log[0].t == Approx(2.0 - std::sqrt(0.625)).epsilon(1e-13));
  // The normal at contact is (-0.79, -0.79, 1) / 1.5: its x and y parts are reversed, z gains.
  const double s = -std::sqrt(0.625);
  const Vec3 nn{s / 1.5, s / 1.5, 1.0 / 1.5};
  const Vec3 v{1, 1, 0};
  const Vec3 expect = v - (2.0 * dot(v, nn)) * nn;
  CHECK(w.velocity(0).x == Approx(expect.x));
  CHECK(w.velocity(0).z == Approx(expect.z));
}

TEST_CASE("two spheres head on with unequal masses: the memo's exchange") {
  World3Def def;
  def.size = {20, 20, 20};
  def.spheres.push_back({{5, 10, 10}, {1, 0, 0}, 1.0, 1.0, 0.0});
  def.spheres.push_back({{12, 10, 10}, {-1, 0, 0}, 1.0, 3.0, 0.0});
  World3 w(def);
  std::vector<Event3> log;
  w.advance_to(3.0, &log);
  REQUIRE(log.size() == 1);
  CHECK(log[0].t == Approx(2.5));
  // 1-D elastic: v1' = ((m1 - m2) v1 + 2 m2 v2) / M = (-2 - 6) / 4 = -2, v2' = (2 + (3 - 1)(-1)... ) = 0.
  CHECK(w.velocity(0).x == Approx(-2.0));
  CHECK(std::abs(w.velocity(1).x) < 1e-15);
}

TEST_CASE("a sphere bouncing under gravity returns to its height every 2 sqrt(2 h / g)") {
  World3Def def;
  def.size = {10, 10, 10};
  def.boundary = Boundary3::walls;
  def.gravity = {0, 0, -9.8};
  def.spheres.push_back({{5, 5, 6}, {0, 0, 0}, 0.5, 1.0, 0.0});
  World3 w(def);
  std::vector<Event3> log;
  const double fall = std::sqrt(2.0 * 5.5 / 9.8);
  w.advance_to(fall + 20 * 2.0 * fall + 1e-3, &log);
  REQUIRE(log.size() == 21);
  for (std::size_t k = 0; k < log.size(); ++k) {
    CHECK(log[k].kind == Event3Kind::ball_wall);
    CHECK(log[k].b == 4);  // the floor, z = 0
    CHECK(log[k].t == Approx(fall + 2.0 * fall * k).epsilon(1e-12));
  }
  CHECK(std::abs(w.energy() - 9.8 * 6.0) < 1e-10 * 9.8 * 6.0);
}

TEST_CASE("toi_sphere_sphere under a relative acceleration finds the second approach the quadratic cannot") {
  // Receding at first (w = +1), pulled back by b = -1: |d| = 3 + t - t^2/2 = 2 at t = 1 + sqrt(3).
  const double t = toi_sphere_sphere({3, 0, 0}, {1, 0, 0}, {-1, 0, 0}, 2.0, 100.0);
  CHECK(t == Approx(1.0 + std::sqrt(3.0)).epsilon(1e-13));
  CHECK(toi_sphere_sphere({3, 0, 0}, {1, 0, 0}, {0, 0, 0}, 2.0, 100.0) == kNever);
}

TEST_CASE("the engine agrees event for event with the brute-force reference (faces, edges, corners)") {
  int kinds[6] = {};
  for (std::uint64_t seed : {1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u}) {
    for (int field = 0; field < 3; ++field) {
      // Free flights; gravity (the same acceleration for all: pairs stay quadratic, walls'
      // edges and corners quartic); an electric field on random charges (pairs quartic too).
      INFO("seed " << seed << " field " << field);
      const World3Def def = random_scene(seed, 8, field == 1, field == 2);
      // Hard spheres are chaotic: only the first 40 events are compared (agree_with_reference).
      turtlegas::test3::agree_with_reference(def, 15.0, kinds);
    }
  }
  INFO("pairs " << kinds[0] << " faces " << kinds[1] << " edges " << kinds[2] << " corners " << kinds[3]);
  CHECK(kinds[0] > 50);
  CHECK(kinds[1] > 50);
  CHECK(kinds[2] >= 3);
  CHECK(kinds[3] >= 1);
}

TEST_CASE("a gas in a box with polygons: energy and overlap kept over 10^5 collisions") {
  for (bool gravity : {false, true}) {
    INFO((gravity ? "gravity" : "free"));
    World3Def def;
    def.size = {30, 30, 30};
    def.boundary = Boundary3::walls;
    if (gravity) def.gravity = {0, 0, -1.0};
    def.walls.push_back({{{5, 5, 10}, {25, 8, 12}, {12, 25, 9}}});
    def.walls.push_back({{{10, 10, 20}, {20, 10, 22}, {20, 20, 22}, {10, 20, 20}}});
    std::mt19937_64 gen(42);
    auto u = [&](double lo, double hi) { return lo + (hi - lo) * static_cast<double>(gen() >> 11) * 0x1.0p-53; };
    for (int k = 0; k < 400; ++k) {
      const Vec3 x{u(1, 29), u(1, 29), u(1, 29)};
      bool ok = true;
      for (const auto& s : def.spheres) ok = ok && norm(s.pos - x) > 2.1;
      for (const auto& wd : def.walls) ok = ok && turtlegas::test3::nearest_on_polygon(wd.corners, x).dist > 1.1;
      if (ok) def.spheres.push_back({x, {u(-3, 3), u(-3, 3), u(-3, 3)}, 1.0, u(0.5, 2.0), 0.0});
    }
    World3 w(def);
    const double e0 = w.energy();
    while (w.collisions() < 100000) w.advance_to(w.time() + 1.0);
    CHECK(std::abs(w.energy() - e0) < 1e-12 * e0 * 10);
    CHECK(w.max_contact_error() < 1e-9);
    CHECK(w.max_overlap_now() < 1e-9);
  }
}

TEST_CASE("a periodic gas keeps its momentum and energy") {
  World3Def def;
  def.size = {20, 20, 20};
  def.boundary = Boundary3::periodic;
  std::mt19937_64 gen(7);
  auto u = [&](double lo, double hi) { return lo + (hi - lo) * static_cast<double>(gen() >> 11) * 0x1.0p-53; };
  while (def.spheres.size() < 500) {
    const Vec3 x{u(0, 20), u(0, 20), u(0, 20)};
    bool ok = true;
    for (const auto& s : def.spheres) {
      Vec3 d = s.pos - x;
      for (int k = 0; k < 3; ++k) d[k] -= 20 * std::nearbyint(d[k] / 20);
      ok = ok && norm(d) > 1.05;
    }
    if (ok) def.spheres.push_back({x, {u(-1, 1), u(-1, 1), u(-1, 1)}, 0.5, 1.0 + (def.spheres.size() % 3), 0.0});
  }
  World3 w(def);
  const Vec3 p0 = w.momentum();
  const double e0 = w.energy();
  while (w.collisions() < 100000) w.advance_to(w.time() + 1.0);
  CHECK(norm(w.momentum() - p0) < 1e-11 * std::sqrt(2 * e0 * 500));
  CHECK(std::abs(w.energy() - e0) < 1e-11 * e0);
  CHECK(w.max_overlap_now() < 1e-9);
  CHECK(w.max_contact_error() < 1e-9);
}
