// SPDX-License-Identifier: MIT
// Clusters (issue 28 item 3; docs/physics.md, "Clusters: a jammed chain"): a row of discs exactly
// filling a box between two walls, one moving, passed its impulse down the row and back at one
// instant for ever (the event log grew by GB in seconds). The row is jammed: the limit takes the
// velocity along it and keeps the rest, with the ledger booking what it took; a row that is free
// at one end (Newton's cradle against a wall) is served one collision at a time, as before.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "scenes.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

namespace {

/// Five discs of radius 2 (masses 1 to 5) in a row at y = 50 from x = `x0`, in a box `width` wide;
/// disc `moving` has velocity v.
WorldDef row(double width, double x0, int moving, Vec2 v, double e) {
  WorldDef d = box(width, 100);
  d.effects.restitution = e;
  for (int k = 0; k < 5; ++k)
    d.balls.push_back(ball("d" + std::to_string(k), {x0 + 2.0 + 4.0 * k, 50.0}, k == moving ? v : Vec2{}, 2.0,
                           1.0 + k));
  return d;
}

}  // namespace

TEST_CASE("a row of discs exactly filling a box, one moving: jammed, the log bounded, the ledger exact",
          "[cluster][squeeze]") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    for (double e : {1.0, 0.5}) {
      for (int moving : {0, 2, 4}) {
        INFO("mode " << (mode == Mode::exact ? "exact" : "step") << ", e = " << e << ", disc " << moving);
        const Vec2 v{3.0, 1.0};
        WorldDef d = row(20.0, 0.0, moving, v, e);
        World w(d, mode);
        w.set_event_limit(10000);  // it served events at one instant for ever
        std::vector<Event> log;
        w.set_event_log(&log);
        const double e0 = w.energy();
        w.advance_to(5.0);
        CHECK(log.size() < 100);
        CHECK(w.stats().wedged >= 1);
        // The moving disc keeps its speed across the row (1 up) and has none along it; the others rest.
        for (int k = 0; k < 5; ++k) {
          const BallState b = w.ball(k);
          CHECK(b.vel.x == 0.0);
          CHECK(b.vel.y == (k == moving ? 1.0 : 0.0));
          CHECK(b.pos.x == Approx(2.0 + 4.0 * k).margin(1e-12));
        }
        const double mass = 1.0 + moving;
        CHECK(w.energy() == Approx(0.5 * mass * 1.0).epsilon(1e-12));
        if (e == 1.0) {
          // Every joule that left is in the ledger: 1/2 m 3^2, by rule and by ball.
          CHECK(e0 - w.energy() == Approx(w.stats().energy_rules()).epsilon(1e-12));
          CHECK(w.stats().energy_wedged == Approx(0.5 * mass * 9.0).epsilon(1e-12));
        } else {
          CHECK(w.stats().energy_rules() <= e0 - w.energy() + 1e-12);
        }
        CHECK(w.max_contact_overlap().relative <= 1e-9);
      }
    }
  }
}

TEST_CASE("a row free at one end is not jammed: Newton's cradle against a wall, energy kept", "[cluster]") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    INFO("mode " << (mode == Mode::exact ? "exact" : "step"));
    // The row touches the right wall only; the first disc comes from the left at 3.
    WorldDef d = box(40.0, 100);
    for (int k = 0; k < 5; ++k) d.balls.push_back(ball("d" + std::to_string(k), {22.0 + 4.0 * k, 50.0}, {}, 2.0));
    d.balls.push_back(ball("m", {12.0, 50.0}, {3.0, 0.0}, 2.0));
    World w(d, mode);
    w.set_event_limit(10000);
    const double e0 = w.energy();
    w.advance_to(4.0);
    CHECK(w.stats().wedged == 0);
    CHECK(w.energy() == Approx(e0).epsilon(1e-12));
    CHECK(w.stats().energy_rules() == 0.0);
    // The impulse ran to the wall and back: the disc that came in leaves at 3 to the left.
    CHECK(w.ball(5).vel.x == Approx(-3.0).epsilon(1e-12));
  }
}
