// SPDX-License-Identifier: MIT
// Walls that move in time: exact collisions with translating walls, momentum transfer.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "scenes.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

TEST_CASE("a ball at rest is struck by a moving wall at the exact time and leaves at twice its speed", "[moving]") {
  WorldDef d = box(200, 100, Boundary::none);
  // x = 100 - 10 t until t = 5.
  d.walls.push_back(moving("piston", {100, 0}, {100, 100}, {{5.0, {50, 0}, {50, 100}}}));
  d.balls.push_back(ball("b", {80, 50}, {0, 0}, 1));
  World w(d, Mode::exact);
  std::vector<Event> log;
  w.set_event_log(&log);
  w.advance_to(3.0);
  REQUIRE(log.size() == 1);
  CHECK(log[0].kind == EventKind::ball_wall);
  CHECK(log[0].t == Approx(1.9).epsilon(1e-12));  // the wall reaches x = 81
  CHECK(w.ball(0).vel.x == Approx(-20).epsilon(1e-12));
  CHECK(w.measure_overlap().relative <= 1e-9);
  // After t = 5 the wall stands at x = 50.
  w.advance_to(6.0);
  CHECK(w.walls()[0].keys.size() == 1);
}

TEST_CASE("a piston compressing a dilute gas heats it as the adiabatic law says (T A^(gamma-1), gamma = 2)", "[moving][physics]") {
  // A 2-D ideal gas has two degrees of freedom per molecule: gamma = 2, so T A is constant. A slow
  // piston (speed 0.1 against thermal speeds of 10) halving the area should double the temperature.
  WorldDef d = box(100, 100, Boundary::none);
  d.walls.push_back({"left", {0, 0}, {0, 100}});
  d.walls.push_back({"bottom", {0, 0}, {120, 0}});
  d.walls.push_back({"top", {0, 100}, {120, 100}});
  d.walls.push_back(moving("piston", {100, 0}, {100, 100}, {{500.0, {50, 0}, {50, 100}}}));
  std::mt19937_64 rng(81);
  auto uniform = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  for (int k = 0; k < 150; ++k) {
    const int row = k / 15, col = k % 15;
    const Vec2 p{3 + col * 6.3, 3 + row * 9.5};
    const double a = 2 * M_PI * uniform();
    d.balls.push_back(ball("g" + std::to_string(k), p, {10 * std::cos(a), 10 * std::sin(a)}, 0.3));
  }
  World w(d, Mode::exact);
  const double e0 = w.energy();
  w.advance_to(500.0);
  const double ratio = w.energy() / e0;
  INFO("temperature ratio " << ratio << " after halving the area");
  CHECK(ratio == Approx(2.0).epsilon(0.08));
  CHECK(w.stats().exits == 0);
  CHECK(w.measure_overlap().relative <= 1e-9);
  for (std::size_t i = 0; i < w.ball_count(); ++i) CHECK(w.ball(i).pos.x <= 50.0);
}

TEST_CASE("a turtle pushed by a moving wall is touched and carried along", "[moving][turtle]") {
  WorldDef d = box(200, 100, Boundary::none);
  // x = 100 - 5 t until t = 10 (x = 50).
  d.walls.push_back(moving("pusher", {100, 0}, {100, 100}, {{10.0, {50, 0}, {50, 100}}}));
  d.turtles.push_back(turtle("t", {50, 50}, 0, 10));
  World w(d, Mode::exact);
  w.advance_to(12.0);
  // Contact when the wall reaches x = 60 (t = 8); pushed to x = 40 by t = 10, then left there.
  const auto contacts = w.take_turtle_contacts();
  REQUIRE(contacts.size() == 1);
  CHECK(contacts[0].kind == EventKind::turtle_wall);
  CHECK(contacts[0].t == Approx(8.0).epsilon(1e-12));
  CHECK(contacts[0].normal.x == Approx(-1));
  CHECK(w.turtle(0).pos.x == Approx(40).epsilon(1e-12));
  CHECK(norm(w.turtle(0).vel) == 0.0);
  CHECK(w.measure_overlap().relative <= 1e-9);
}

TEST_CASE("moving walls: bad keyframes and unsupported uses are clear errors", "[moving]") {
  WorldDef d = box(200, 100);
  d.walls.push_back(moving("p", {100, 10}, {100, 90}, {{5.0, {50, 10}, {50, 90}}}));
  d.walls[0].keys = {{0.0, {50, 10}, {50, 90}}};
  CHECK_THROWS_WITH(World(d, Mode::exact), Catch::Contains("keyframe 0") && Catch::Contains("increase"));
  d.walls[0].keys = {{5.0, {50, 10}, {50, 90}}, {4.0, {50, 10}, {50, 90}}};
  CHECK_THROWS_WITH(World(d, Mode::exact), Catch::Contains("keyframe 1") && Catch::Contains("increase"));
  d.walls[0].keys = {{5.0, {50, 10}, {50, 10}}};
  CHECK_THROWS_WITH(World(d, Mode::exact), Catch::Contains("zero length"));
  // The ends swap places: on the way the wall would be a point.
  d.walls[0].keys = {{5.0, {100, 90}, {100, 10}}};
  CHECK_THROWS_WITH(World(d, Mode::exact), Catch::Contains("shrink to a point"));
  // Turning by 180 degrees in one step is the same; two steps of 90 degrees are fine.
  d.walls[0].keys = {{5.0, {60, 50}, {140, 50}}, {10.0, {100, 90}, {100, 10}}};
  CHECK_NOTHROW(World(d, Mode::exact));
  d.arena.boundary = Boundary::periodic;
  CHECK_THROWS_WITH(World(d, Mode::exact), Catch::Contains("periodic"));
  // A wall added at run time cannot move.
  WorldDef e = box(200, 100);
  e.walls.push_back(moving("p", {100, 10}, {100, 90}, {{5.0, {50, 10}, {50, 90}}}));
  World w(e, Mode::exact);
  WallDef late{"late", {10, 10}, {10, 90}};
  late.keys = {{5.0, {20, 10}, {20, 90}}};
  CHECK_THROWS_WITH(w.add_wall(late), Catch::Contains("cannot move"));
}

TEST_CASE("moving walls in step mode: the memo's loop with the wall moving inside each step", "[moving][step]") {
  WorldDef d = box(200, 100, Boundary::none);
  d.dt = 0.1;
  d.walls.push_back(moving("piston", {100, 0}, {100, 100}, {{5.0, {50, 0}, {50, 100}}}));
  d.balls.push_back(ball("b", {80, 50}, {0, 0}, 1));
  World w(d, Mode::step);
  std::vector<Event> log;
  w.set_event_log(&log);
  w.advance_to(3.0);
  REQUIRE(log.size() == 1);
  CHECK(log[0].kind == EventKind::ball_wall);
  CHECK(log[0].t == Approx(1.9).epsilon(1e-12));
  CHECK(w.ball(0).vel.x == Approx(-20).epsilon(1e-12));
  // Past the keyframe the wall stands still; the run goes on (no keyframe left to hang on).
  w.advance_to(8.0);
  CHECK(w.measure_overlap().relative <= 1e-9);
  // The same piston in both modes heats the gas alike.
  WorldDef g = box(100, 100, Boundary::none);
  g.walls.push_back({"left", {0, 0}, {0, 100}});
  g.walls.push_back({"bottom", {0, 0}, {120, 0}});
  g.walls.push_back({"top", {0, 100}, {120, 100}});
  g.walls.push_back(moving("piston", {100, 0}, {100, 100}, {{100.0, {70, 0}, {70, 100}}}));
  for (int k = 0; k < 60; ++k) {
    const int row = k / 10, col = k % 10;
    g.balls.push_back(ball("g" + std::to_string(k), {4 + col * 9.0, 5 + row * 15.0},
                           {10 * std::cos(k * 2.4), 10 * std::sin(k * 2.4)}, 0.3));
  }
  World exact(g, Mode::exact), step(g, Mode::step);
  exact.advance_to(100.0);
  step.advance_to(100.0);
  CHECK(step.energy() == Approx(exact.energy()).epsilon(0.02));
  CHECK(step.energy() > 1.2 * 0.5 * 60 * 100);
  CHECK(step.measure_overlap().relative <= 1e-9);
}

TEST_CASE("a wall that comes and goes in time", "[moving][visibility]") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    INFO((mode == Mode::exact ? "exact" : "step"));
    WorldDef d = box(200, 100, Boundary::none);
    d.dt = 0.1;
    WallDef gate{"gate", {100, 0}, {100, 100}};
    gate.visibility = {{1.0, false}, {12.0, true}};  // there, gone from t = 1, back from t = 12
    d.walls.push_back(gate);
    d.balls.push_back(ball("early", {95, 30}, {10, 0}, 1));   // would hit it at t = 0.4
    d.balls.push_back(ball("through", {50, 70}, {10, 0}, 1));  // reaches x = 99 at t = 4.9: gone
    World w(d, mode);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.advance_to(10.0);
    REQUIRE(log.size() == 1);
    CHECK(log[0].a == 0);
    CHECK(log[0].t == Approx(0.4).epsilon(1e-12));
    CHECK(w.ball(1).pos.x == Approx(150));
    // Back at t = 12: the ball bouncing back from the left (none there; it flies on) is not caught
    // inside it. A ball arriving later is stopped again.
    WorldDef e = d;
    e.balls = {ball("late", {20, 50}, {10, 0}, 1)};  // x = 99 at t = 7.9 (gone), then past
    e.walls[0].visibility = {{1.0, false}, {5.0, true}};
    World w2(e, mode);
    w2.advance_to(10.0);
    CHECK(w2.stats().ball_wall == 1);  // back in place by t = 5, hit at t = 7.9
    CHECK(w2.ball(0).vel.x == Approx(-10));
  }
}

TEST_CASE("a turtle carried by a moving wall is not touched again when another wall reaches a keyframe", "[moving][turtle]") {
  // Issue 17, section 4: a `door` wall's keyframe at t = 7 used to end the pusher's push (and
  // re-aim the pusher by round-off), so the pusher struck the turtle a second time at t = 7.
  for (Mode mode : {Mode::exact, Mode::step}) {
    INFO("mode " << (mode == Mode::exact ? "exact" : "step"));
    WorldDef d = box(400, 300);
    d.walls.push_back(moving("pusher", {20, 200}, {20, 280}, {{15.0, {180, 200}, {180, 280}}}));
    d.walls.push_back(moving("door", {300, 0}, {300, 100}, {{7.0, {300, 0}, {300, 50}}}));
    d.turtles.push_back(turtle("t", {60, 240}, 0, 10));
    World w(d, mode);
    w.set_event_limit(100000);
    w.advance_to(14.0);
    const auto contacts = w.take_turtle_contacts();
    REQUIRE(contacts.size() == 1);
    // The pusher (160/15 units/s from x = 20) reaches x = 50 at t = 2.8125.
    CHECK(contacts[0].t == Approx(2.8125).epsilon(1e-9));
    // Carried at the pusher's speed ever since: at t = 14 the pusher is at 20 + 14 * 160/15.
    CHECK(w.turtle(0).pos.x == Approx(20 + 14 * 160.0 / 15 + 10).epsilon(1e-9));
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}
