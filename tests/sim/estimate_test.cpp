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
