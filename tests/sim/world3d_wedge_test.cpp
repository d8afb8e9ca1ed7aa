// SPDX-License-Identifier: MIT
// The 3-D wedge rule (docs/physics.md, "3-D: wedged spheres"): a sphere in a slot or a tube
// exactly its width, or in a box it fills, bounced between opposite walls at one instant for ever
// (the run never returned, SIGTERM unseen). The rule takes the velocity along the pair, books it,
// and acts nowhere else: a sphere into a corner of three walls bounces out exactly, a gas never
// wedges. The event limit and the stop poll end an advance that does not.
#include <catch2/catch.hpp>

#include <cmath>

#include "turtlegas/sim/world3d.hpp"

using namespace turtlegas::sim;

namespace {

World3Def box_with(Vec3 size, Vec3 pos, Vec3 vel, double e = 1.0) {
  World3Def def;
  def.size = size;
  def.boundary = Boundary3::walls;
  def.spheres.push_back({pos, vel, 1.0, 2.0, 0.0, e});
  return def;
}

}  // namespace

TEST_CASE("a sphere in a slot exactly its width keeps its motion along the slot", "[wedge]") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    for (double e : {1.0, 0.5}) {
      INFO("e " << e << (mode == Mode::step ? ", step mode" : ""));
      World3Def def = box_with({20, 10, 2}, {5, 5, 1}, {1, 0.5, 0.3}, e);
      def.mode = mode;
      World3 w(def);
      w.set_event_limit(1000);
      const double e0 = w.energy();
      std::vector<Event3> log;
      w.advance_to(2.0, &log);
      CHECK(w.wedged() == 1);
      CHECK(w.events() < 50u);
      REQUIRE(!log.empty());
      CHECK(log[0].kind == Event3Kind::wedged);
      CHECK(log[0].t == 0.0);
      // Along the slot, the flight it had; across it, nothing: z stays 1.
      CHECK(w.velocity(0).z == 0.0);
      CHECK(w.velocity(0).x == 1.0);
      CHECK(w.velocity(0).y == 0.5);
      CHECK(w.position(0).z == 1.0);
      CHECK(w.position(0).x == Approx(7.0).epsilon(1e-14));
      CHECK(w.position(0).y == Approx(6.0).epsilon(1e-14));
      CHECK(w.energy_wedged() == Approx(0.5 * 2.0 * 0.09).epsilon(1e-14));
      CHECK(e0 - w.energy() == Approx(w.energy_wedged()).epsilon(1e-12));
    }
  }
}

TEST_CASE("a sphere in a square tube exactly its width, and in a box it fills", "[wedge]") {
  SECTION("tube: only the motion along it is kept") {
    World3 w(box_with({20, 2, 2}, {5, 1, 1}, {1, 0.5, 0.3}));
    w.set_event_limit(1000);
    w.advance_to(2.0);
    CHECK(w.wedged() == 2);
    CHECK(w.velocity(0).x == 1.0);
    CHECK(w.velocity(0).y == 0.0);
    CHECK(w.velocity(0).z == 0.0);
    CHECK(w.position(0).x == Approx(7.0).epsilon(1e-14));
    CHECK(w.energy_wedged() == Approx(0.5 * 2.0 * (0.25 + 0.09)).epsilon(1e-14));
  }
  SECTION("box: everything is taken") {
    World3 w(box_with({2, 2, 2}, {1, 1, 1}, {1, 0.5, 0.3}));
    w.set_event_limit(1000);
    w.advance_to(2.0);
    CHECK(w.wedged() == 3);
    CHECK(w.kinetic_energy() == 0.0);
    CHECK(w.energy_wedged() == Approx(0.5 * 2.0 * (1.0 + 0.25 + 0.09)).epsilon(1e-14));
  }
}

TEST_CASE("the rule does not act where the bounces end: a corner of three walls, a slot wider than the sphere", "[wedge]") {
  SECTION("into a corner (touching three walls, none opposite): reversed, energy kept") {
    World3 w(box_with({10, 10, 10}, {1, 1, 1}, {-1, -0.5, -0.3}));
    w.set_event_limit(1000);
    std::vector<Event3> log;
    w.advance_to(0.5, &log);
    CHECK(w.wedged() == 0);
    CHECK(log.size() == 3u);
    CHECK(w.velocity(0).x == 1.0);
    CHECK(w.velocity(0).y == 0.5);
    CHECK(w.velocity(0).z == Approx(0.3).epsilon(1e-15));
  }
  SECTION("a slot 1e-6 wider: bounces across it at their times, energy kept") {
    World3 w(box_with({20, 10, 2 + 1e-6}, {5, 5, 1}, {1, 0.5, 0.3}));
    w.set_event_limit(100000);
    const double e0 = w.energy();
    w.advance_to(1e-4);
    CHECK(w.wedged() == 0);
    CHECK(w.collisions() == Approx(1e-4 * 0.3 / 1e-6).margin(2));
    CHECK(w.energy() == Approx(e0).epsilon(1e-13));
  }
  SECTION("another sphere touching it across the slot's normal: the rule acts, the other keeps its flight") {
    // Two spheres in the slot touching side by side along x: that contact is across the slot's
    // normal (z), so no bounce between the faces can close it.
    World3Def def = box_with({20, 10, 2}, {5, 5, 1}, {0, 0, 0.3});
    def.spheres.push_back({{7, 5, 1}, {0.25, 0, 0}, 1.0, 1.0, 0.0, 1.0});
    World3 w(def);
    w.set_event_limit(1000);
    w.advance_to(1.0);
    CHECK(w.wedged() == 1);
    CHECK(w.velocity(0).z == 0.0);
    CHECK(w.velocity(1).x == 0.25);
  }
}

TEST_CASE("a gas in a box never wedges", "[wedge]") {
  World3Def def;
  def.size = {12, 12, 12};
  def.boundary = Boundary3::walls;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        def.spheres.push_back({{2.0 + 4.0 * i, 2.0 + 4.0 * j, 2.0 + 4.0 * k},
                               {std::sin(1.0 + i + 3 * j + 9 * k), std::cos(2.0 + i * j + k), std::sin(3.0 * i - j + k)},
                               1.0, 1.0, 0.0, 1.0});
  World3 w(def);
  const double e0 = w.energy();
  w.advance_to(50.0);
  CHECK(w.collisions() > 500u);
  CHECK(w.wedged() == 0);
  CHECK(w.energy() == Approx(e0).epsilon(1e-12));
}

TEST_CASE("an advance that does not end stops at the event limit or the poll, consistent", "[wedge]") {
  // Two spheres in a row exactly filling a box along x (a jammed row: 2-D's jammed chain, not
  // built in 3-D; a sphere in line is not the wedge's) bounce at one instant for ever.
  World3Def def;
  def.size = {4, 10, 10};
  def.boundary = Boundary3::walls;
  def.spheres.push_back({{1, 5, 5}, {1, 0, 0}, 1.0, 1.0, 0.0, 1.0});
  def.spheres.push_back({{3, 5, 5}, {0, 0, 0}, 1.0, 1.0, 0.0, 1.0});
  SECTION("event limit") {
    World3 w(def);
    w.set_event_limit(5000);
    CHECK_THROWS_AS(w.advance_to(1.0), EventLimitReached);
    CHECK(w.events() == 5000u);
    CHECK(w.time() == 0.0);
  }
  SECTION("stop poll") {
    World3 w(def);
    int polls = 0;
    w.set_stop_poll([&] { return ++polls == 3; }, 1000);
    CHECK_THROWS_AS(w.advance_to(1.0), StopRequested);
    CHECK(polls == 3);
    CHECK(w.events() == 3000u);
  }
}
