// SPDX-License-Identifier: MIT
// Balls' trails (formats/ball_trails.hpp) follow the flight: on a charge's circle, and through the
// collisions of a charged gas to where the engine has every ball.
#include <catch2/catch.hpp>
#include <cmath>
#include <sstream>

#include "../sim/scenes.hpp"
#include "turtlegas/formats/ball_trails.hpp"
#include "turtlegas/formats/svg_snapshot.hpp"

using namespace turtlegas;

TEST_CASE("a charge's trail in B lies on its circle, not on chords", "[formats][trails]") {
  sim::WorldDef d = test::box(1000, 1000);
  d.effects.magnetic = 0.5;
  sim::BallDef b = test::ball("p", {500.0, 503.0}, {3.0, 0.0}, 0.5, 1.0);
  b.charge = 2.0;  // w = 1: radius 3 about (500, 500)
  d.balls.push_back(b);
  sim::World w(d, sim::Mode::exact);
  formats::BallTrails trails(d, 1.0);
  w.advance_to(1.0);
  trails.start(w);
  w.advance_to(1.0 + 2.0 * M_PI * 1.5);  // a turn and a half
  trails.finish(w);
  const auto lines = trails.polylines();
  REQUIRE(lines.size() == 1);
  CHECK(lines[0].size() >= 72);  // 48 points a turn
  for (const sim::Vec2 p : lines[0]) CHECK(std::abs(std::hypot(p.x - 500.0, p.y - 500.0) - 3.0) <= 1e-12);
  // A chord between two consecutive points of a 48-gon would sag 3 (1 - cos(pi/48)) = 6e-3 at its
  // middle: the points are on the circle, the picture is a 72-gon at worst.
  CHECK(trails.end_mismatch() <= 1e-12);
  formats::Snapshot s = formats::snapshot_of(w, d);
  s.ball_trails = lines;
  std::ostringstream svg;
  formats::write_svg(svg, s);
  CHECK(svg.str().find("class=\"ball-trail\"") != std::string::npos);
}

TEST_CASE("trails of a charged gas under g, E and B end where the engine has every ball", "[formats][trails]") {
  sim::WorldDef d = test::random_gas(200, 0.2, 1.0, 3.0, 77);
  d.effects.gravity = {0.0, -0.3};
  d.effects.electric = {0.4, 0.0};
  d.effects.magnetic = 0.7;
  for (std::size_t i = 0; i < d.balls.size(); ++i) d.balls[i].charge = i % 3 == 0 ? 0.0 : (i % 3 == 1 ? 1.0 : -2.0);
  sim::World w(d, sim::Mode::exact);
  std::vector<sim::Impulse> log;
  w.set_impulse_log(&log);
  formats::BallTrails trails(d, 2.0);
  w.advance_to(2.0);
  log.clear();
  trails.start(w);
  for (double t = 2.5; t <= 12.0; t += 0.5) {
    w.advance_to(t);
    trails.take(log);
    log.clear();
  }
  INFO("collisions " << w.stats().collisions());
  REQUIRE(w.stats().ball_ball > 200);
  trails.finish(w);
  // Each ball flown from its state at t = 2 through every impulse: the engine's positions to
  // round-off (a trail that missed an impulse would be off by up to the box).
  CHECK(trails.end_mismatch() <= 1e-8);
  // Without the impulses the trails go astray: the check can fail.
  formats::BallTrails blind(d, 2.0);
  sim::World w2(d, sim::Mode::exact);
  w2.advance_to(2.0);
  blind.start(w2);
  w2.advance_to(12.0);
  blind.finish(w2);
  CHECK(blind.end_mismatch() > 1.0);
}
