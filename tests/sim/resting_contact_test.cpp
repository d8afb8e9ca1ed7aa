// SPDX-License-Identifier: MIT
// Resting contact under gravity (issue 17, section 5b): a disc resting on a straight slope, and on
// a turtle far from the origin, hops at the t_c scale (the rest threshold) and never sinks. The
// overlap is sampled over the run, not only at its end; every run is bounded by an event limit.
#include <catch2/catch.hpp>

#include <cmath>

#include "scenes.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

TEST_CASE("a disc resting on one straight 10-degree slope under gravity does not sink into it", "[rest]") {
  // It once got "never" from the first-approach root when a few ulps inside and receding slowly
  // with gravity pulling it back, and sank 0.54 of a radius within 2 s.
  for (double tc : {1e-6, 1e-7}) {
    INFO("tc = " << tc);
    const double a = 10.0 * M_PI / 180.0;
    const Vec2 u{std::cos(a), std::sin(a)}, n{-std::sin(a), std::cos(a)};
    WorldDef d = box(300, 200);
    const Vec2 o{20, 20};
    d.walls.push_back({"slope", o, o + 250.0 * u});
    d.effects.gravity = {0, -10};
    d.effects.restitution = 0.5;
    d.effects.tc = tc;
    d.balls.push_back(ball("b", o + 150.0 * u + (1.0 + 1e-12) * n, {0, 0}, 1));  // (exactly 1 overlaps by round-off)
    World w(d, Mode::exact);
    w.set_event_limit(400000);
    const double until = tc * 5e4;  // some 5e4 hops at most
    const double worst = deepest_over_run(w, until, 50);
    CHECK(worst <= 1e-9);
    // It slides down the slope (frictionless): g sin(a) t^2 / 2 along -u, to 1e-6 of that.
    const double along = dot(w.ball(0).pos - o, u);
    CHECK(150.0 - along == Approx(0.5 * 10 * std::sin(a) * until * until).epsilon(1e-3));
  }
}

TEST_CASE("a disc resting on a turtle far from the origin does not sink into it", "[rest][turtle]") {
  // At y = 1e4 with tc = 1e-6 it once sank 4.9 radii into the turtle (the quartic's same hole).
  WorldDef d = box(200, 2e4);
  d.effects.gravity = {0, -10};
  d.effects.restitution = 0.5;
  d.effects.tc = 1e-6;
  d.turtles.push_back(turtle("t", {100, 1e4}, 0, 10));
  d.balls.push_back(ball("b", {100.5, 1e4 + 11.0}, {0, 0}, 1));
  World w(d, Mode::exact);
  w.set_event_limit(400000);
  const double worst = deepest_over_run(w, 0.05, 50);
  CHECK(worst <= 1e-9);
}
