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

namespace {

const char* name(Mode mode) { return mode == Mode::exact ? "exact" : "step"; }

/// N equal discs of radius 1 in a row at y = 50 exactly filling a box 2N wide (each touching the
/// next, the ends touching both walls); disc `moving` has velocity v.
WorldDef filled(int n, int moving, Vec2 v, double e) {
  WorldDef d = box(2.0 * n, 100);
  d.effects.restitution = e;
  for (int k = 0; k < n; ++k)
    d.balls.push_back(ball("d" + std::to_string(k), {1.0 + 2.0 * k, 50.0}, k == moving ? v : Vec2{}, 1.0));
  return d;
}

/// Runs to `until` with an event limit and a log; the log's size.
std::size_t run_logged(World& w, double until) {
  w.set_event_limit(100000);  // it served events at one instant for ever
  std::vector<Event> log;
  w.set_event_log(&log);
  w.advance_to(until);
  return log.size();
}

}  // namespace

TEST_CASE("rows of 2, 3 and 10 equal discs filling a box: the run ends, positions and the ledger exact",
          "[cluster][squeeze]") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    for (int n : {2, 3, 10}) {
      for (double e : {1.0, 0.5}) {
        for (int moving : {0, n / 2, n - 1}) {
          for (double dir : {1.0, -1.0}) {
            INFO("mode " << name(mode) << ", N = " << n << ", e = " << e << ", disc " << moving << ", dir " << dir);
            World w(filled(n, moving, {2.0 * dir, 0.5}, e), mode);
            const double e0 = w.energy();
            const std::size_t events = run_logged(w, 3.0);
            CHECK(events < 10u * static_cast<std::size_t>(n));
            CHECK(w.stats().wedged == 1);
            for (int k = 0; k < n; ++k) {
              CHECK(w.ball(k).pos.x == Approx(1.0 + 2.0 * k).margin(1e-12));  // positions unchanged
              CHECK(w.ball(k).vel.x == 0.0);
              CHECK(w.ball(k).vel.y == (k == moving ? 0.5 : 0.0));  // across the row: kept
            }
            // What the rule took is in the ledger: 1/2 m 2^2 at e = 1; at e < 1 the bounces before
            // it took their share (restitution's, not booked).
            const double taken = w.stats().energy_rules();
            if (e == 1.0) CHECK(e0 - w.energy() == Approx(2.0).epsilon(1e-12));
            if (e == 1.0) CHECK(taken == Approx(2.0).epsilon(1e-12));
            CHECK(taken <= e0 - w.energy() + 1e-12);
            CHECK(w.energy() == Approx(0.5 * 0.25).epsilon(1e-12));
            CHECK(w.max_contact_overlap().relative <= 1e-9);
          }
        }
      }
    }
  }
}

TEST_CASE("a row touching one wall only at e = 1 is not jammed: the far disc leaves with the mover's speed",
          "[cluster]") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    for (int n : {2, 3, 10}) {
      // The row touches the left wall of a box 4N wide; the mover is the first disc (at the wall,
      // moving away from it) or the last (moving towards it).
      for (int moving : {0, n - 1}) {
        INFO("mode " << name(mode) << ", N = " << n << ", disc " << moving);
        const double v = moving == 0 ? 3.0 : -3.0;
        WorldDef d = filled(n, moving, {v, 0.0}, 1.0);
        d.arena.width = 4.0 * n;
        World w(d, mode);
        const double e0 = w.energy();
        const std::size_t events = run_logged(w, 0.25);
        CHECK(events <= 2u * static_cast<std::size_t>(n));
        CHECK(w.stats().wedged == 0);
        CHECK(w.stats().energy_rules() == 0.0);
        CHECK(w.energy() == Approx(e0).epsilon(1e-12));
        // Momentum passed through the row (and off the wall): only the last disc moves, at 3.
        for (int k = 0; k + 1 < n; ++k) CHECK(std::abs(w.ball(k).vel.x) <= 1e-12);
        CHECK(w.ball(n - 1).vel.x == Approx(3.0).epsilon(1e-12));
        CHECK(w.ball(n - 1).pos.x == Approx(2.0 * n - 1.0 + 0.75).epsilon(1e-12));
      }
    }
  }
}

TEST_CASE("a row of unequal discs touching one wall only at e = 1: the sequence ends, energy kept", "[cluster]") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    INFO("mode " << name(mode));
    WorldDef d = row(60.0, 0.0, 4, {-3.0, 0.0}, 1.0);  // masses 1..5 at the left wall, the heaviest moving
    World w(d, mode);
    const double e0 = w.energy();
    const std::size_t events = run_logged(w, 1.0);
    CHECK(events < 200u);
    CHECK(w.stats().wedged == 0);
    CHECK(w.stats().energy_rules() == 0.0);
    CHECK(w.energy() == Approx(e0).epsilon(1e-12));
    CHECK(w.max_contact_overlap().relative <= 1e-9);
  }
}

TEST_CASE("a row between a wall and a standing turtle, or a wall's end, is jammed too", "[cluster][squeeze]") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    for (int end : {0, 1}) {
      INFO("mode " << name(mode) << (end == 0 ? ", a turtle" : ", a wall's end"));
      // Four discs of radius 1 from the left wall along y = 50; the fifth place is the far end.
      WorldDef d = box(100, 100);
      for (int k = 0; k < 4; ++k)
        d.balls.push_back(ball("d" + std::to_string(k), {1.0 + 2.0 * k, 50.0}, k == 1 ? Vec2{-2.0, 0.25} : Vec2{}, 1.0,
                               1.0 + k));
      if (end == 0) d.turtles.push_back(turtle("t", {8.0 + 5.0, 50.0}, 0, 5));  // touches d3 at x = 8
      else d.walls.push_back(WallDef{"shelf", {8.0, 50.0}, {30.0, 50.0}});  // its end at x = 8, in line
      World w(d, mode);
      const double e0 = w.energy();
      const std::size_t events = run_logged(w, 3.0);
      CHECK(events < 40u);
      CHECK(w.stats().wedged == 1);
      for (int k = 0; k < 4; ++k) {
        CHECK(w.ball(k).pos.x == Approx(1.0 + 2.0 * k).margin(1e-12));
        CHECK(w.ball(k).vel.x == 0.0);
      }
      CHECK(w.ball(1).vel.y == 0.25);
      CHECK(e0 - w.energy() == Approx(w.stats().energy_rules()).epsilon(1e-12));
      CHECK(w.stats().energy_wedged == Approx(0.5 * 2.0 * 4.0).epsilon(1e-12));
      CHECK(w.max_contact_overlap().relative <= 1e-9);
    }
  }
}

namespace {

/// Three discs of radius 12.5 filling a box 75 wide, d0 moving at 2 along the row, and a fourth,
/// "top", on d1 at an angle: touching it along m = (7, 24)/25 (placed exactly: no round-off), or
/// 1e-9 above that. Masses 1 (`heavy`: d_k has 1 + k).
WorldDef row_with_top(double e, bool touching, bool heavy) {
  WorldDef d = box(75, 100);
  d.effects.restitution = e;
  for (int k = 0; k < 3; ++k)
    d.balls.push_back(ball("d" + std::to_string(k), {12.5 + 25.0 * k, 50.0}, k == 0 ? Vec2{2.0, 0.0} : Vec2{}, 12.5,
                           heavy ? 1.0 + k : 1.0));
  d.balls.push_back(ball("top", {37.5 + 7.0, 74.0 + (touching ? 0.0 : 1e-9)}, {}, 12.5));
  return d;
}

}  // namespace

TEST_CASE("a row touched at an angle: the rule acts once the row's sequence cannot reach the contact", "[cluster]") {
  const Vec2 m{7.0 / 25.0, 24.0 / 25.0};
  for (Mode mode : {Mode::exact, Mode::step}) {
    SECTION(std::string("a disc 1e-9 above the row, ") + name(mode)) {
      // Not in contact: the zero-time sequence is over before the gap closes, so it is the row's
      // alone (the limit: every speed along the row 0, booked), and "top" is not touched.
      for (double e : {1.0, 0.5}) {
        World w(row_with_top(e, false, false), mode);
        const std::size_t events = run_logged(w, 0.01);
        CHECK(events < 10u);
        CHECK(w.stats().wedged == 1);
        CHECK(w.ball(3).vel.x == 0.0);
        CHECK(w.ball(3).vel.y == 0.0);
        for (int k = 0; k < 3; ++k) CHECK(w.ball(k).vel.x == 0.0);
      }
    }
    SECTION(std::string("a disc touching the row, ") + name(mode)) {
      // In contact: each impulse "top" takes is along m and opens the contact; the rule waits
      // until the bound (the row's energy along it) proves the row cannot reach "top" again, or the
      // sequence returns to a state it had (equal masses at e = 1: the impulse passes d1 on before
      // its contact with "top" comes up, and "top" is never touched).
      for (double e : {1.0, 0.9, 0.5}) {
        for (bool heavy : {false, true}) {
          INFO("e " << e << (heavy ? ", masses 1, 2, 3" : ", equal masses"));
          World w(row_with_top(e, true, heavy), mode);
          const double e0 = w.energy();
          const std::size_t events = run_logged(w, 0.01);
          CHECK(events < 400u);
          CHECK(w.stats().wedged == 1);
          const Vec2 v = w.ball(3).vel;
          CHECK(std::abs(v.x * m.y - v.y * m.x) <= 1e-15);  // only d1 pushed it
          for (int k = 0; k < 3; ++k) CHECK(w.ball(k).vel.x == 0.0);
          const double along = v.x * m.x + v.y * m.y;
          CHECK(along >= 0.0);
          if (e == 1.0 && !heavy) CHECK(along == 0.0);
          if (heavy || e < 1.0) CHECK(along > 0.01);
          // At e = 1 nothing but the rule takes energy: the ledger is the rest.
          if (e == 1.0) CHECK(e0 - w.energy() == Approx(w.stats().energy_rules()).epsilon(1e-12));
          CHECK(w.max_contact_overlap().relative <= 1e-9);
        }
      }
    }
  }
}

TEST_CASE("a row touched at an angle by a disc in a groove (the scene that ran to the event limit)", "[cluster]") {
  // Three discs filling a box 6 wide, a fourth on the middle two at 60 degrees (1e-14 up: round
  // off). The contact is not closed at t = 0 (its gap is positive), so the row is answered alone.
  for (Mode mode : {Mode::exact, Mode::step}) {
    INFO("mode " << name(mode));
    WorldDef d = filled(3, 0, {2.0, 0.0}, 1.0);
    d.balls.push_back(ball("top", {4.0, 50.0 + std::sqrt(3.0) + 1e-14}, {}, 1.0));
    World w(d, mode);
    const std::size_t events = run_logged(w, 0.01);
    CHECK(events < 20u);
    CHECK(w.stats().wedged == 1);
    CHECK(w.stats().energy_rules() == Approx(2.0).epsilon(1e-12));
  }
}

TEST_CASE("a row along a diagonal between two walls across it: jammed, the ledger exact", "[cluster][squeeze]") {
  // Rows of 3 and 10 discs along (1, 1)/sqrt 2 between two walls across it (1e-12 of room per
  // contact, within the overlap budget: placed exactly, round-off would overlap them); d0 moves at
  // 2 along the row and 0.3 across it.
  for (Mode mode : {Mode::exact, Mode::step}) {
    for (int n : {3, 10}) {
      INFO("mode " << name(mode) << ", N = " << n);
      const Vec2 u{1.0 / std::sqrt(2.0), 1.0 / std::sqrt(2.0)}, across{-u.y, u.x}, c{30.0, 30.0};
      const double g = 1e-12;
      WorldDef d = box(100, 100);
      for (int k = 0; k < n; ++k)
        d.balls.push_back(ball("d" + std::to_string(k), c + (2.0 + g) * k * u, k == 0 ? 2.0 * u - 0.3 * across : Vec2{}));
      auto wall = [&](std::string id, double s) {
        const Vec2 p = c + s * u;
        return WallDef{std::move(id), p - 5.0 * across, p + 5.0 * across};
      };
      d.walls.push_back(wall("w0", -1.0 - g));
      d.walls.push_back(wall("w1", (2.0 + g) * (n - 1) + 1.0 + g));
      World w(d, mode);
      const double e0 = w.energy();
      const std::size_t events = run_logged(w, 3.0);
      CHECK(events < 10u * static_cast<std::size_t>(n));
      CHECK(w.stats().wedged == 1);
      for (int k = 0; k < n; ++k) {
        // Along the row: exactly what the rule leaves. Across: the room of 1e-12 lets d0 drift
        // 0.3 x 5e-13 across before it meets d1, which tilts that collision's normal by 7.5e-14
        // and passes 1.5e-13 of the speed 2 across (the exact physics of that room, not round-off).
        CHECK(std::abs(dot(w.ball(k).vel, u)) <= 1e-15);
        CHECK(dot(w.ball(k).vel, across) == Approx(k == 0 ? -0.3 : 0.0).margin(1e-12));
      }
      CHECK(e0 - w.energy() == Approx(w.stats().energy_rules()).epsilon(1e-12));
      CHECK(w.stats().energy_rules() == Approx(2.0).epsilon(1e-12));
      CHECK(w.max_contact_overlap().relative <= 1e-9);
    }
  }
}
