// SPDX-License-Identifier: MIT
// sim::estimate_work: a run's cost from the scene's scales, against runs that measure it.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "scenes.hpp"
#include "turtlegas/sim/estimate.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

TEST_CASE("estimate_work is within a factor of three of a dilute gas's measured collisions", "[estimate]") {
  for (double phi : {0.02, 0.1}) {
    INFO("phi " << phi);
    const WorldDef d = random_gas(400, phi, 1.0, 10.0, 7);
    const WorkEstimate e = estimate_work(d, Mode::exact, 20.0);
    World w(d, Mode::exact);
    w.set_event_limit(5000000);
    w.advance_to(20.0);
    const double measured = static_cast<double>(w.stats().collisions());
    const double predicted = e.collisions_per_s * 20.0;
    INFO("measured " << measured << ", predicted " << predicted);
    CHECK(predicted > measured / 3.0);
    CHECK(predicted < measured * 3.0);
    const double events = static_cast<double>(w.stats().events);
    CHECK(e.events > events / 3.0);
    CHECK(e.events < events * 3.0);
  }
}

TEST_CASE("estimate_work says absurd in numbers, and stays finite", "[estimate]") {
  WorldDef d = box(100, 100);
  d.balls.push_back(ball("b", {50, 50}, {1e150, 0}, 1));
  const WorkEstimate fast = estimate_work(d, Mode::exact, 10.0);
  CHECK(fast.events > 1e148);
  CHECK(std::isfinite(fast.events));
  d.balls[0].vel = {1, 0};
  d.dt = 1e-300;
  const WorkEstimate tiny = estimate_work(d, Mode::step, 1e308);
  CHECK(tiny.steps_per_s == Approx(1e300));
  CHECK(tiny.events == std::numeric_limits<double>::max());
}

TEST_CASE("estimate_work: the fields' acceleration, |g| + |q| |E| / m, over the arena's larger side", "[estimate]") {
  WorldDef d = box(100, 50);
  d.effects.gravity = {0, -1};
  d.effects.electric = {3, 4};  // |E| = 5
  BallDef b = ball("b", {50, 25}, {1, 0}, 1, 4);
  b.charge = -2;  // a = 1 + 2 * 5 / 4 = 3.5, whatever the charge's sign
  d.balls.push_back(b);
  d.balls.push_back(ball("slow", {20, 20}, {0, 2}));  // neutral: gravity only, sqrt(2 * 100) + 2
  const WorkEstimate e = estimate_work(d, Mode::exact, 1.0, 5.0);
  const double fast = 1.0 + std::sqrt(2.0 * 3.5 * 100.0), slow = 2.0 + std::sqrt(2.0 * 1.0 * 100.0);
  CHECK(e.max_speed == Approx(fast).epsilon(1e-12));
  CHECK(e.fastest == 0);
  CHECK(e.by_fields);
  CHECK(e.speed_sum == Approx(2.0 * (fast + slow)).epsilon(1e-12));
  CHECK(e.cell == 5.0);
  CHECK(e.crossings_per_s == Approx(2.0 * (fast + slow) / 5.0).epsilon(1e-12));
  CHECK(e.events_per_s == e.crossings_per_s);
  CHECK(e.cause == WorkCause::fields);
  // Walls at v / L, L the smaller side, and the pair term 2 sigma n v / 2 (sigma = 2 r_max).
  const double n = 2.0 / (100.0 * 50.0);
  CHECK(e.collisions_per_s == Approx((fast + slow) / 50.0 + 2.0 * n * (fast + slow)).epsilon(1e-12));
  CHECK(e.events == Approx(e.collisions_per_s + e.crossings_per_s).epsilon(1e-12));
  CHECK(e.steps_per_s == 0.0);  // exact mode, no turtles
}

TEST_CASE("estimate_work: turtles and their turning, control steps, the fastest body's index", "[estimate]") {
  WorldDef d = box(100, 100);
  d.dt = 0.02;
  d.balls.push_back(ball("b", {50, 50}, {3, 4}, 1));  // 5 units/s
  TurtleDef t = turtle("t", {20, 20}, 0, 2, 4);
  t.turn_rate = -3;  // 4 + 3 * 2 = 10 units/s at its rim
  d.turtles.push_back(t);
  WorkEstimate e = estimate_work(d, Mode::exact, 2.0, 10.0);
  CHECK(e.max_speed == Approx(10.0));
  CHECK(e.fastest == 1);  // def.turtles[1 - def.balls.size()]
  CHECK_FALSE(e.by_fields);
  CHECK(e.speed_sum == Approx(2.0 * 5.0 + 10.0));
  CHECK(e.crossings_per_s == Approx(2.0));
  CHECK(e.cause == WorkCause::speed);
  CHECK(e.steps_per_s == Approx(50.0));  // the control steps, in exact mode too
  // Step mode: the same steps (the control steps are the mode's steps), and the run counts them.
  e = estimate_work(d, Mode::step, 2.0, 10.0);
  CHECK(e.steps_per_s == Approx(50.0));
  CHECK(e.events == Approx((e.collisions_per_s + 50.0) * 2.0));
}

TEST_CASE("estimate_work: exact mode's re-plans of gyrating ions, |q Bz / m| / (16 pi) each", "[estimate]") {
  WorldDef d = box(100, 100);
  d.effects.magnetic = 0.5;
  BallDef ion = ball("ion", {50, 50}, {1, 0}, 1, 2);
  ion.charge = 1e6;  // |q B / m| = 2.5e5 rad/s
  BallDef small = ball("small", {20, 20}, {0, 1}, 1, 1);
  small.charge = -4;  // 2 rad/s
  d.balls = {small, ion, ball("neutral", {80, 80}, {1, 1})};
  WorkEstimate e = estimate_work(d, Mode::exact, 1.0, 4.0);
  CHECK(e.replans_per_s == Approx((2.5e5 + 2.0) / (16.0 * M_PI)).epsilon(1e-12));
  CHECK(e.turns_per_s == Approx(2.5e5 / (2.0 * M_PI)).epsilon(1e-12));
  CHECK(e.gyrating == 1);
  CHECK(e.events_per_s == Approx(e.crossings_per_s + e.replans_per_s).epsilon(1e-12));
  CHECK(e.cause == WorkCause::gyration);  // ~5e3 re-plans against a few crossings
  CHECK(e.events == Approx(e.collisions_per_s + e.events_per_s).epsilon(1e-12));
  // A cell small enough that the crossings dominate again.
  e.set_cell(1e-6);
  CHECK(e.cause == WorkCause::speed);
  CHECK(e.crossings_per_s == Approx(e.speed_sum / 1e-6));
  e.set_cell(0.0);  // not a cell: changes nothing
  CHECK(e.cell == 1e-6);
  // Step mode never re-plans a circle.
  CHECK(estimate_work(d, Mode::step, 1.0).replans_per_s == 0.0);
  d.effects.magnetic = 0.0;
  CHECK(estimate_work(d, Mode::exact, 1.0).replans_per_s == 0.0);
}

TEST_CASE("estimate_work counts a gyrating ion's events as a run makes them", "[estimate]") {
  // An ion beside another charged ball of another q/m (check's fuzzed scene, scaled down, its
  // circle kept off the cells' borders): exact mode re-plans the ion's circle every 8 turns, about
  // 1000 events in 10 s; the estimate must be above them, within a factor of a few.
  WorldDef d = box(100, 100);
  d.effects.magnetic = 0.5;
  BallDef ion = ball("ion", {40, 60}, {30, 0}, 1, 1);
  ion.charge = 4.0 * M_PI * 800.0;  // 800 turns a second
  BallDef other = ball("other", {20, 20}, {0, 3}, 1, 1);
  other.charge = 1;
  d.balls = {ion, other};
  const WorkEstimate e = estimate_work(d, Mode::exact, 10.0);
  World w(d, Mode::exact);
  w.set_event_limit(100000);
  w.advance_to(10.0);
  const double events = static_cast<double>(w.stats().events);
  INFO("measured " << events << ", predicted " << e.events << ", re-plans " << e.replans_per_s * 10.0);
  CHECK(e.events >= events);
  CHECK(e.events < events * 4.0);
}
