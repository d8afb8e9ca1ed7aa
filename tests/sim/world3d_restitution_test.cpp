// SPDX-License-Identifier: MIT
// 3-D restitution (docs/physics.md, "3-D: restitution"): the energy a bounce takes in closed form,
// the pair's rule (the larger e, the TC rule), a wall's product, the rest threshold that ends a
// Zeno sequence of bounces on a floor, the TC rule that ends an inelastic collapse, and agreement
// event for event with the reference.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "reference3d.hpp"
#include "turtlegas/sim/world3d.hpp"

using namespace turtlegas::sim;

TEST_CASE("a face bounce keeps e_sphere * e_wall of the normal speed: energy loss (1 - e^2) m vn^2 / 2") {
  for (double es : {1.0, 0.8, 0.3}) {
    for (double ew : {1.0, 0.5, 0.0}) {
      INFO("e_sphere " << es << " e_wall " << ew);
      World3Def def;
      def.size = {20, 20, 20};
      def.spheres.push_back({{5, 5, 7}, {0.5, 0.25, -2}, 1.0, 3.0, 0.0, es});
      def.walls.push_back({{{2, 2, 1}, {8, 2, 1}, {8, 8, 1}, {2, 8, 1}}, ew});
      World3 w(def);
      const double e0 = w.kinetic_energy();
      std::vector<Event3> log;
      w.advance_to(3.0, &log);
      REQUIRE(log.size() == 1);
      CHECK(log[0].t == Approx(2.5).epsilon(1e-14));
      const double e = es * ew;
      // At e = 0 the departure floor, 2^-40 of the speed (up to the round-off of adding it to v).
      CHECK(w.velocity(0).z == Approx(std::max(2.0 * e, 0x1p-40 * std::sqrt(4.3125))).epsilon(1e-14).margin(1e-15));
      CHECK(w.velocity(0).x == Approx(0.5).epsilon(1e-15));
      CHECK(w.velocity(0).y == Approx(0.25).epsilon(1e-15));
      CHECK(e0 - w.kinetic_energy() == Approx(0.5 * (1 - e * e) * 3.0 * 4.0).margin(1e-12));
    }
  }
}

TEST_CASE("a pair takes the larger e of its spheres: 1-D closed form, momentum kept, loss (1 - e^2) mu vn^2 / 2") {
  World3Def def;
  def.size = {20, 20, 20};
  def.spheres.push_back({{5, 10, 10}, {1, 0, 0}, 1.0, 1.0, 0.0, 0.3});
  def.spheres.push_back({{12, 10, 10}, {-1, 0, 0}, 1.0, 3.0, 0.0, 0.7});
  World3 w(def);
  const double k0 = w.kinetic_energy();
  const Vec3 p0 = w.momentum();
  std::vector<Event3> log;
  w.advance_to(3.0, &log);
  REQUIRE(log.size() == 1);
  CHECK(log[0].t == Approx(2.5));
  // e = 0.7: v1' = (m1 v1 + m2 v2 + m2 e (v2 - v1)) / M = (1 - 3 - 4.2) / 4, v2' = (1 - 3 + 1.4) / 4.
  CHECK(w.velocity(0).x == Approx(-1.55).epsilon(1e-14));
  CHECK(w.velocity(1).x == Approx(-0.15).epsilon(1e-14));
  CHECK(norm(w.momentum() - p0) < 1e-15);
  const double mu = 3.0 / 4.0;
  CHECK(k0 - w.kinetic_energy() == Approx(0.5 * (1 - 0.49) * mu * 4.0).epsilon(1e-13));
}

TEST_CASE("the TC rule: a sphere that changed course less than tc ago collides elastically") {
  // Sphere 0 strikes 1, which touches 2: at one instant 0-1 (e), then 1-2 and 1-0 (elastic by the
  // TC rule, 1 changed course just now). Equal masses: 0 stops, 1 keeps (1 - e)/2, 2 takes (1 + e)/2.
  // Without the rule 1-2 would take e too: 2 would leave at (1 + e)^2 / 4.
  const double e = 0.5;
  World3Def def;
  def.size = {30, 20, 20};
  def.spheres.push_back({{5, 10, 10}, {1, 0, 0}, 1.0, 1.0, 0.0, e});
  def.spheres.push_back({{10, 10, 10}, {0, 0, 0}, 1.0, 1.0, 0.0, e});
  def.spheres.push_back({{12, 10, 10}, {0, 0, 0}, 1.0, 1.0, 0.0, e});
  World3 w(def);
  std::vector<Event3> log;
  w.advance_to(4.0, &log);
  REQUIRE(log.size() == 3);
  for (const Event3& ev : log) CHECK(ev.t == Approx(3.0));
  CHECK(std::abs(w.velocity(0).x) < 1e-15);
  CHECK(w.velocity(1).x == Approx((1 - e) / 2).epsilon(1e-14));
  CHECK(w.velocity(2).x == Approx((1 + e) / 2).epsilon(1e-14));
  // With tc = 0 there is no rule: the second contact takes e as well.
  def.tc = 0.0;
  World3 plain(def);
  plain.advance_to(4.0);
  CHECK(plain.velocity(2).x == Approx((1 + e) * (1 + e) / 4).epsilon(1e-14));
}

TEST_CASE("inelastic collapse: three spheres at e = 0.05 end in finitely many collisions under the TC rule") {
  // Two outer spheres close on a resting middle one in a line; below e = 7 - 4 sqrt(3) the middle
  // one is struck infinitely often in finite time (McNamara & Young) in exact arithmetic. The TC
  // rule ends it in 7 collisions; without it (tc = 0) only the departure floor does, after 45
  // (the relative speeds shrink by about e a collision down to 2^-40 of the speeds).
  World3Def def;
  def.size = {40, 20, 20};
  def.tc = 1e-3;
  def.spheres.push_back({{5, 10, 10}, {1, 0, 0}, 1.0, 1.0, 0.0, 0.05});
  def.spheres.push_back({{14, 10, 10}, {0, 0, 0}, 1.0, 1.0, 0.0, 0.05});
  def.spheres.push_back({{26, 10, 10}, {-1.3, 0, 0}, 1.0, 1.0, 0.0, 0.05});
  World3 w(def);
  const Vec3 p0 = w.momentum();
  const double k0 = w.kinetic_energy();
  w.advance_to(20.0);
  CHECK(w.time() == 20.0);
  CHECK(w.collisions() <= 10);
  CHECK(w.collisions() >= 3);
  def.tc = 0.0;
  World3 plain(def);
  plain.advance_to(20.0);
  CHECK(plain.collisions() > 2 * w.collisions());
  CHECK(plain.collisions() < 200);
  CHECK(plain.max_overlap_now() < 1e-9);
  CHECK(norm(w.momentum() - p0) < 1e-14);
  CHECK(w.kinetic_energy() < k0);
  CHECK(w.max_overlap_now() < 1e-9);
  CHECK(w.max_contact_error() < 1e-9);
}

TEST_CASE("the rest threshold: a sphere bouncing to rest at e = 0.5 hops every tc instead of a Zeno sequence") {
  const double g = 10.0, tc = 1e-4, h = 4.5, e = 0.5;
  World3Def def;
  def.size = {10, 10, 10};
  def.boundary = Boundary3::walls;
  def.gravity = {0, 0, -g};
  def.tc = tc;
  def.spheres.push_back({{5, 5, h + 0.5}, {0, 0, 0}, 0.5, 1.0, 0.0, e});
  World3 w(def);
  std::vector<Event3> log;
  w.advance_to(4.0, &log);
  // The first bounces in closed form: t1 = sqrt(2h/g), then each flight 2 e^k v1 / g.
  const double v1 = std::sqrt(2 * g * h);
  double t = std::sqrt(2 * h / g);
  for (int k = 0; k < 10; ++k) {
    INFO("bounce " << k);
    REQUIRE(log.size() > 10);
    CHECK(log[k].kind == Event3Kind::ball_wall);
    CHECK(log[k].t == Approx(t).epsilon(1e-11));
    t += 2 * std::pow(e, k + 1) * v1 / g;
  }
  // The Zeno limit is t1 + 2 e v1 / (g (1 - e)) = 2.85 s; after it the sphere hops every tc.
  const double t_inf = std::sqrt(2 * h / g) + 2 * e * v1 / (g * (1 - e));
  CHECK(log.size() < 1000 + static_cast<std::size_t>((4.0 - t_inf) / tc * 1.01));
  REQUIRE(log.back().t > 3.9);
  const double hop = log.back().t - log[log.size() - 2].t;
  CHECK(hop == Approx(tc).epsilon(1e-6));
  CHECK(w.position(0).z < 0.5 + g * tc * tc / 8 * 1.001);
  CHECK(w.max_overlap_now() < 1e-9);
}

TEST_CASE("with restitution the engine agrees event for event with the reference") {
  int inelastic_events = 0;
  for (std::uint64_t seed : {11u, 12u, 13u, 14u, 15u, 16u}) {
    for (int field = 0; field < 3; ++field) {
      if (field == 2 && seed > 12) continue;  // the reference crawls through electric scenes: two are enough
      INFO("seed " << seed << " field " << field);
      World3Def def = turtlegas::test3::random_scene(seed, 8, field == 1, field == 2);
      std::mt19937_64 gen(seed * 7 + static_cast<unsigned>(field));
      auto u = [&](double lo, double hi) { return lo + (hi - lo) * static_cast<double>(gen() >> 11) * 0x1.0p-53; };
      for (auto& s : def.spheres) s.restitution = u(0.5, 1.0);
      for (auto& wd : def.walls) wd.restitution = u(0.6, 1.0);
      def.tc = 1e-3;
      World3 w(def);
      std::vector<Event3> fast, slow;
      // Up to the first 31 events: a sphere pressed onto a wall comes to rest there in time and
      // hops every tc, which the reference's small steps would crawl through.
      while (fast.size() < 31 && w.time() < 10.0) w.advance_to(w.time() + 0.05, &fast);
      turtlegas::test3::Reference3 ref(def);
      ref.run(w.time(), slow, fast.size() + 1);
      const std::size_t n = std::min<std::size_t>(std::min(fast.size(), slow.size()), 30);
      REQUIRE(n >= 10);
      for (std::size_t k = 0; k < n; ++k) {
        INFO("event " << k << " t " << fast[k].t << " vs " << slow[k].t);
        REQUIRE(fast[k].kind == slow[k].kind);
        if (fast[k].kind == Event3Kind::ball_ball) {
          REQUIRE(std::min(fast[k].a, fast[k].b) == slow[k].a);
          REQUIRE(std::max(fast[k].a, fast[k].b) == slow[k].b);
        } else {
          REQUIRE(fast[k].a == slow[k].a);
          REQUIRE(fast[k].b == slow[k].b);
          REQUIRE(fast[k].c == slow[k].c);
        }
        REQUIRE(std::abs(fast[k].t - slow[k].t) < 1e-7);
        ++inelastic_events;
      }
      CHECK(w.max_overlap_now() < 1e-9);
    }
  }
  CHECK(inelastic_events > 250);
}

TEST_CASE("a periodic inelastic gas keeps its momentum, loses energy, never overlaps") {
  World3Def def;
  def.size = {20, 20, 20};
  def.boundary = Boundary3::periodic;
  std::mt19937_64 gen(9);
  auto u = [&](double lo, double hi) { return lo + (hi - lo) * static_cast<double>(gen() >> 11) * 0x1.0p-53; };
  while (def.spheres.size() < 400) {
    const Vec3 x{u(0, 20), u(0, 20), u(0, 20)};
    bool ok = true;
    for (const auto& s : def.spheres) {
      Vec3 d = s.pos - x;
      for (int k = 0; k < 3; ++k) d[k] -= 20 * std::nearbyint(d[k] / 20);
      ok = ok && norm(d) > 1.05;
    }
    if (ok) def.spheres.push_back({x, {u(-1, 1), u(-1, 1), u(-1, 1)}, 0.5, 1.0 + (def.spheres.size() % 3), 0.0, 0.9});
  }
  World3 w(def);
  const Vec3 p0 = w.momentum();
  const double k0 = w.kinetic_energy();
  while (w.collisions() < 20000) w.advance_to(w.time() + 1.0);
  CHECK(norm(w.momentum() - p0) < 1e-11 * std::sqrt(2 * k0 * 400));
  // Each collision takes (1 - e^2)/2 = 9.5 % of its pair's normal energy: the gas cools (Haff).
  CHECK(w.kinetic_energy() < 0.8 * k0);
  CHECK(w.max_overlap_now() < 1e-9);
  CHECK(w.max_contact_error() < 1e-9);
}
