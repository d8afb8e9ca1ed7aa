// SPDX-License-Identifier: MIT
// Turtles in the physics: commanded motion, dead stops at contact, contacts for the touch sensors.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "scenes.hpp"
#include "turtlegas/sim/toi.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

namespace {

const Mode kModes[] = {Mode::exact, Mode::step};
const char* name(Mode m) { return m == Mode::exact ? "exact" : "step"; }
constexpr double kDeg = M_PI / 180.0;

TurtleCommand move(double d) { return {TurtleCommand::Kind::move, d}; }
TurtleCommand turn(double deg) { return {TurtleCommand::Kind::turn, deg * kDeg}; }

}  // namespace

TEST_CASE("forward stops exactly at the contact, with the contact normal", "[turtle]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(400, 200);
    d.walls.push_back({"east", {100, 0}, {100, 200}});
    d.turtles.push_back(turtle("t", {50, 50}, 90));  // heading 90: +x
    World w(d, mode);
    w.command_turtle(0, move(1000));
    w.advance_to(3.0);
    const TurtleState s = w.turtle(0);
    // Contact when the centre is one radius from the wall: x = 90, after 40 units = 4/3 s.
    CHECK(s.pos.x == Approx(90).epsilon(1e-14));
    CHECK(s.pos.y == Approx(50).epsilon(1e-14));
    CHECK_FALSE(s.busy);
    CHECK(s.touched);
    CHECK(s.done == Approx(40).epsilon(1e-12));
    CHECK(norm(s.vel) == 0.0);
    const auto contacts = w.take_turtle_contacts();
    REQUIRE(contacts.size() == 1);
    CHECK(contacts[0].kind == EventKind::turtle_wall);
    CHECK(contacts[0].other == 0);
    CHECK(contacts[0].t == Approx(4.0 / 3.0).epsilon(1e-12));
    CHECK(contacts[0].normal.x == Approx(-1));
    CHECK(contacts[0].normal.y == Approx(0).margin(1e-15));
    CHECK(w.take_turtle_contacts().empty());
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}

TEST_CASE("a command completes between boundaries and the turtle waits there", "[turtle]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(400, 400);
    d.turtles.push_back(turtle("t", {100, 100}, 0));  // heading 0: +y
    World w(d, mode);
    w.command_turtle(0, move(25));
    w.advance_to(0.5);
    CHECK(w.turtle(0).busy);
    CHECK(w.turtle(0).done == Approx(15));
    w.advance_to(2.0);
    const TurtleState s = w.turtle(0);
    CHECK_FALSE(s.busy);
    CHECK_FALSE(s.touched);
    CHECK(s.done == Approx(25));
    CHECK(s.pos.y == Approx(125).epsilon(1e-14));
    CHECK(s.pos.x == Approx(100).epsilon(1e-14));
    w.command_turtle(0, move(-5));  // back
    w.advance_to(3.0);
    CHECK(w.turtle(0).pos.y == Approx(120).epsilon(1e-14));
  }
}

TEST_CASE("turning takes time at the turn rate and never collides", "[turtle]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(400, 400);
    d.walls.push_back({"w", {50, 0}, {50, 400}});
    d.turtles.push_back(turtle("t", {60, 100}, 0));  // touching the wall
    World w(d, mode);
    w.command_turtle(0, turn(360));
    w.advance_to(2.0);
    CHECK(w.turtle(0).heading == Approx(180 * kDeg));
    CHECK(w.turtle(0).busy);
    w.advance_to(5.0);
    CHECK(w.turtle(0).heading == Approx(360 * kDeg));
    CHECK_FALSE(w.turtle(0).busy);
    CHECK(w.take_turtle_contacts().empty());
    CHECK(w.stats().collisions() == 0);
    // Left is a negative turn.
    w.command_turtle(0, turn(-90));
    w.advance_to(7.0);
    CHECK(w.turtle(0).heading == Approx(270 * kDeg));
  }
}

TEST_CASE("touching: driving into the wall stops at once, driving away does not", "[turtle]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(400, 400);
    d.walls.push_back({"w", {50, 0}, {50, 400}});
    d.turtles.push_back(turtle("t", {60, 100}, 270));  // touching, facing the wall (-x)
    World w(d, mode);
    w.command_turtle(0, move(10));
    w.advance_to(1.0);
    CHECK(w.turtle(0).touched);
    CHECK(w.turtle(0).done == Approx(0).margin(1e-12));
    CHECK(w.turtle(0).pos.x == Approx(60));
    CHECK(w.take_turtle_contacts().size() == 1);
    w.command_turtle(0, move(-10));  // backwards, away from the wall
    w.advance_to(2.0);
    CHECK_FALSE(w.turtle(0).touched);
    CHECK(w.turtle(0).pos.x == Approx(70));
    CHECK(w.take_turtle_contacts().empty());
  }
}

TEST_CASE("two turtles meeting head on both stop at contact", "[turtle]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(400, 400);
    d.turtles.push_back(turtle("a", {100, 200}, 90));
    d.turtles.push_back(turtle("b", {200, 200}, 270));
    World w(d, mode);
    w.command_turtle(0, move(100));
    w.command_turtle(1, move(100));
    w.advance_to(3.0);
    CHECK(w.turtle(0).pos.x == Approx(140));
    CHECK(w.turtle(1).pos.x == Approx(160));
    CHECK(w.turtle(0).touched);
    CHECK(w.turtle(1).touched);
    auto contacts = w.take_turtle_contacts();
    REQUIRE(contacts.size() == 2);
    CHECK(contacts[0].kind == EventKind::turtle_turtle);
    CHECK(contacts[0].normal.x == -contacts[1].normal.x);
    CHECK(w.stats().turtle_turtle == 1);
  }
}

TEST_CASE("a ball bounces off a turtle, which stops dead at the touch", "[turtle]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(400, 400);
    d.turtles.push_back(turtle("t", {200, 200}, 90, 10, 20));  // moving +x at 20
    d.balls.push_back(ball("b", {260, 200}, {-10, 0}, 2));
    World w(d, mode);
    w.command_turtle(0, move(100));
    w.advance_to(3.0);
    // Closing speed 30 over a gap of 48: contact at 1.6 s. The turtle stops dead there; the ball
    // then bounces off it as off a wall of infinite mass at rest, leaving at +10.
    CHECK(w.stats().turtle_ball == 1);
    CHECK(w.ball(0).vel.x == Approx(10));
    CHECK(w.turtle(0).touched);
    CHECK(w.turtle(0).pos.x == Approx(232));
    const auto c = w.take_turtle_contacts();
    REQUIRE(c.size() == 1);
    CHECK(c[0].kind == EventKind::turtle_ball);
    CHECK(c[0].t == Approx(1.6));
  }
  SECTION("a still turtle hit by a ball reflects it elastically") {
    WorldDef d = box(400, 400);
    d.turtles.push_back(turtle("t", {200, 200}, 0));
    d.balls.push_back(ball("b", {260, 230}, {-30, -10}, 2));
    World w(d, Mode::exact);
    const double e0 = w.energy();
    w.advance_to(3.0);
    CHECK(w.stats().turtle_ball == 1);
    CHECK(w.energy() == Approx(e0).epsilon(1e-14));
    CHECK(w.turtle(0).pos.x == 200.0);
  }
}

TEST_CASE("a turtle turning or waiting at rest is still struck when its predictions say", "[turtle]") {
  // Commands that leave a turtle standing still (turn, wait) keep the collisions already predicted
  // with it rather than predicting again; these scenes fail if one is lost or left stale.
  // A ball of radius 2 at x = 260 closes on the still turtle (radius 10, x = 200) at 30 units/s:
  // contact after 48 units, at t = 1.6.
  const Mode mode = GENERATE(Mode::exact, Mode::step);
  INFO(name(mode));
  {
    WorldDef d = box(400, 400);
    d.dt = 0.1;
    d.turtles.push_back(turtle("t", {200, 200}, 0));  // turns at 90 degrees/s
    d.balls.push_back(ball("b", {260, 200}, {-30, 0}, 2));
    SECTION("struck after a turn and a wait from rest, when only the turtle foresaw it") {
      // The ball falls along x = 185 at 10 units/s, missing the turtle where it starts (x = 200,
      // 15 > 12 away) and while it drives to x = 185 (done at t = 0.5, the ball 55 above). So the
      // ball foresees nothing; the turtle, stopping, predicts the contact itself: 43 units closed
      // at 10, at t = 4.8. It then turns and waits; those commands must keep that prediction. (One
      // cell spans the arena, so no cell crossing makes the ball look round again.)
      d.arena.cell = 400;
      d.turtles[0].heading = 270 * kDeg;  // towards -x
      d.balls[0].pos = {185, 260};
      d.balls[0].vel = {0, -10};
      World w(d, mode);
      w.command_turtle(0, move(15));  // 0.5 s at 30
      w.advance_to(1.0);
      CHECK_FALSE(w.turtle(0).busy);
      CHECK(w.turtle(0).pos.x == Approx(185).epsilon(1e-14));
      w.command_turtle(0, turn(45));  // 0.5 s
      w.advance_to(2.0);
      CHECK_FALSE(w.turtle(0).busy);
      CHECK(w.turtle(0).heading == Approx(315 * kDeg).epsilon(1e-14));
      w.command_turtle(0, {TurtleCommand::Kind::wait, 0.5});
      w.advance_to(6.0);
      CHECK(w.stats().turtle_ball == 1);
      CHECK(w.ball(0).vel.y == Approx(10).epsilon(1e-12));
      const auto c = w.take_turtle_contacts();
      REQUIRE(c.size() == 1);
      CHECK(c[0].t == Approx(4.8).epsilon(1e-12));
      CHECK(w.turtle(0).pos.x == Approx(185).epsilon(1e-14));
      CHECK_FALSE(w.turtle(0).touched);  // the wait had ended: nothing was cut short
      CHECK(w.measure_overlap().relative <= 1e-9);
    }
    SECTION("struck in the middle of a turn, which the touch cuts short") {
      World w(d, mode);
      w.command_turtle(0, turn(90));
      w.advance_to(1.3);
      w.command_turtle(0, turn(-90));  // from 90 degrees back towards 0; struck 0.3 s in
      w.advance_to(3.0);
      const TurtleState s = w.turtle(0);
      CHECK(s.touched);
      CHECK_FALSE(s.busy);
      CHECK(s.done == Approx(27 * kDeg).epsilon(1e-12));
      CHECK(s.heading == Approx(63 * kDeg).epsilon(1e-12));
      CHECK(w.stats().turtle_ball == 1);
      CHECK(w.take_turtle_contacts().at(0).t == Approx(1.6).epsilon(1e-12));
    }
    SECTION("a turtle that set off towards the still one, then stopped, does not reach it") {
      // The second turtle's stop changes its course after the still turtle's last prediction:
      // that prediction is stale and must not fire.
      WorldDef e = box(400, 400);
      e.dt = 0.1;
      e.turtles.push_back(turtle("still", {200, 200}, 0));
      e.turtles.push_back(turtle("mover", {100, 200}, 90));  // towards +x at 30: contact at 80 units
      World w(e, mode);
      w.command_turtle(1, move(60));  // stops 20 short of contact, at t = 2
      w.command_turtle(0, turn(45));
      w.advance_to(0.5);
      w.command_turtle(0, turn(45));
      w.advance_to(4.0);
      CHECK(w.stats().turtle_turtle == 0);
      CHECK(w.turtle(1).pos.x == Approx(160).epsilon(1e-14));
      CHECK(w.turtle(0).heading == Approx(M_PI / 2).epsilon(1e-14));
    }
  }
}

TEST_CASE("a turtle with bounce set rebounds and coasts to the next control step", "[turtle]") {
  WorldDef d = box(400, 200);
  d.dt = 0.1;
  d.walls.push_back({"east", {100, 0}, {100, 200}});
  TurtleDef t = turtle("t", {80, 50}, 90);
  t.bounce = 0.5;
  d.turtles.push_back(t);
  World w(d, Mode::exact);
  w.command_turtle(0, move(1000));
  w.advance_to(1.0);
  // Contact at x = 90 after 1/3 s; back at 15 units/s until t = 0.4, so 1/15 s of coasting.
  CHECK(w.turtle(0).pos.x == Approx(90 - 15.0 / 15.0).epsilon(1e-9));
  CHECK(norm(w.turtle(0).vel) == 0.0);
  CHECK(w.turtle(0).touched);
}

TEST_CASE("a hundred turtles driven at random stay apart and inside", "[turtle][stress]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(1000, 1000);
    d.walls.push_back({"x1", {200, 200}, {500, 300}});
    d.walls.push_back({"x2", {700, 100}, {650, 700}});
    d.walls.push_back({"x3", {300, 800}, {600, 650}});
    for (int k = 0; k < 100; ++k) {
      const int row = k / 10, col = k % 10;
      const double x = 50 + 90 * col + 20, y = 50 + 90 * row + 15;
      d.turtles.push_back(turtle("t" + std::to_string(k), {x, y}, 0, 6, 40));
    }
    // Keep only turtles clear of the walls.
    std::vector<TurtleDef> keep;
    for (const auto& t : d.turtles) {
      bool clear = true;
      for (const auto& wd : d.walls) {
        const Segment s = make_segment(wd.from, wd.to);
        const double foot = std::clamp(dot(t.pos - s.p1, s.u), 0.0, s.len);
        clear = clear && norm(t.pos - s.p1 - foot * s.u) > t.radius;
      }
      if (clear) keep.push_back(t);
    }
    d.turtles = keep;
    World w(d, mode);
    std::mt19937_64 rng(7);
    auto uniform = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
    std::uint64_t touches = 0;
    std::uint64_t idle_mismatches = 0;  // idle_turtles() against turtle(k).busy, turtle by turtle
    std::vector<std::uint32_t> idle, expected;
    for (int step = 1; step <= 3000; ++step) {
      idle.clear();
      expected.clear();
      w.idle_turtles(idle);
      for (std::uint32_t k = 0; k < w.turtle_count(); ++k)
        if (!w.turtle(k).busy) expected.push_back(k);
      if (idle != expected) ++idle_mismatches;
      for (std::size_t k = 0; k < w.turtle_count(); ++k) {
        const TurtleState s = w.turtle(k);
        if (s.busy) continue;
        if (s.touched || uniform() < 0.3) w.command_turtle(k, turn(uniform() * 360 - 180));
        else w.command_turtle(k, move(uniform() * 200));
      }
      w.advance_to(step * d.dt);
      touches += w.take_turtle_contacts().size();
    }
    CHECK(touches > 500);
    CHECK(idle_mismatches == 0);
    CHECK(w.measure_overlap().relative <= 1e-9);
    CHECK(w.stats().exits == 0);
    for (std::size_t k = 0; k < w.turtle_count(); ++k) {
      const TurtleState s = w.turtle(k);
      REQUIRE(is_finite(s.pos));
      REQUIRE(s.pos.x >= 6 - 1e-9);
      REQUIRE(s.pos.x <= 994 + 1e-9);
      REQUIRE(s.pos.y >= 6 - 1e-9);
      REQUIRE(s.pos.y <= 994 + 1e-9);
    }
  }
}

TEST_CASE("a ball that catches a moving turtle from behind bounces off the stopped turtle", "[turtle][regression]") {
  // Bounced against the turtle's velocity before it stopped, the ball kept closing on it and, with
  // the pair marked as just collided, sank into it (0.16 units here, 0.67 in step mode).
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(200, 400);
    d.balls.push_back(ball("b", {100, 50}, {10, 60}, 3));
    d.turtles.push_back(turtle("t", {100, 100}, 0, 14, 30));
    World w(d, mode);
    w.command_turtle(0, move(150));
    for (int k = 1; k <= 120; ++k) {
      w.advance_to(k * d.dt);
      if (!w.turtle(0).busy) w.command_turtle(0, {TurtleCommand::Kind::wait, 2.0});
      REQUIRE(w.measure_overlap().relative <= 1e-9);
    }
    CHECK(w.stats().turtle_ball >= 1);
    CHECK(std::abs(w.energy() - 0.5 * (100 + 3600)) <= 1e-9 * 1850);  // the stopped turtle gives no energy
  }
}

TEST_CASE("after touching a wall and turning 90 degrees, a turtle drives along it", "[turtle][regression]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(400, 400);
    d.walls.push_back({"w", {50, 0}, {50, 400}});
    d.turtles.push_back(turtle("t", {100, 100}, 270));  // facing the wall (-x)
    World w(d, mode);
    w.command_turtle(0, move(100));
    w.advance_to(3.0);
    REQUIRE(w.turtle(0).touched);
    w.command_turtle(0, turn(90));  // now facing +y, the wall on the left, exactly parallel
    w.advance_to(5.0);
    w.command_turtle(0, move(60));
    w.advance_to(9.0);
    CHECK_FALSE(w.turtle(0).touched);
    CHECK(w.turtle(0).done == Approx(60));
    CHECK(w.turtle(0).pos.y == Approx(160));
    CHECK(w.turtle(0).pos.x == 60.0);
  }
}

TEST_CASE("in a periodic arena a touch on the far part of a long wall has the right normal", "[turtle][periodic]") {
  // A wall longer than half the arena: near its far end the nearest image of the turtle measured
  // from the wall's first end is not the one touching it (the contact normal once came out flipped).
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(100, 100, Boundary::periodic);
    d.dt = 0.05;
    d.walls.push_back({"long", {5, 20}, {95, 63.5}});
    d.turtles.push_back(turtle("t", {85, 50}, 0, 1, 10));  // below the wall, driving up (+y)
    World w(d, mode);
    w.command_turtle(0, move(100));
    w.advance_to(2.0);
    const auto contacts = w.take_turtle_contacts();
    REQUIRE(contacts.size() == 1);
    const Vec2 u = Vec2{90, 43.5} / std::hypot(90, 43.5);
    const Vec2 towards_turtle{u.y, -u.x};  // the wall's normal on the turtle's (lower) side
    CHECK(contacts[0].normal.x == Approx(towards_turtle.x).epsilon(1e-12));
    CHECK(contacts[0].normal.y == Approx(towards_turtle.y).epsilon(1e-12));
    // Stopped one radius below the line: its height there, 20 + 43.5 * 80 / 90, less 1 / cos.
    CHECK(w.turtle(0).pos.y == Approx(20 + 43.5 * 80 / 90 - 1 / u.x).epsilon(1e-12));
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}

TEST_CASE("a turtle that touches a slanted wall, turns along it and drives on is not stopped by a graze", "[turtle]") {
  // Issue 17: at 30 degrees the turn left the turtle "approaching" the wall at 1e-16 of its
  // speed, and it stopped at once; at 45 it drove the full 50 units.
  for (Mode mode : kModes) {
    for (double deg : {10.0, 30.0, 45.0, 60.0, 75.0}) {
      INFO(name(mode) << ", wall at " << deg << " degrees");
      const double a = deg * kDeg;
      const Vec2 u{std::cos(a), std::sin(a)}, n{-std::sin(a), std::cos(a)};
      const Vec2 mid{200, 150};
      WorldDef d = box(400, 300);
      d.walls.push_back({"slope", mid - 150.0 * u, mid + 150.0 * u});
      // Heading towards the wall (-n): Logo heading h has the vector (sin h, cos h).
      const double h = std::atan2(-n.x, -n.y) / kDeg;
      d.turtles.push_back(turtle("t", mid + 30.0 * n, h));
      World w(d, mode);
      w.set_event_limit(100000);
      w.command_turtle(0, move(100));
      w.advance_to(2.0);
      REQUIRE(w.turtle(0).touched);
      w.command_turtle(0, turn(-90));  // left: now along +u
      w.advance_to(4.0);
      w.command_turtle(0, move(50));
      w.advance_to(8.0);
      const TurtleState s = w.turtle(0);
      CHECK_FALSE(s.touched);
      CHECK(s.done == Approx(50).epsilon(1e-12));
      CHECK(w.measure_overlap().relative <= 1e-9);
    }
  }
}

// The world fuzzer's finding (issue 29): a command whose end lies 10^105 s away (forward 2.4e107
// at speed 60, or an arc of radius 7.8e58) cast its control-step index, 1.2e107, to a 64-bit
// integer (undefined behaviour; UBSan in the debug-asan subset stops on it). The command runs on
// as any other, and its end is not snapped to a step no run reaches.
TEST_CASE("a command that ends astronomically far away runs on and ends nothing early", "[turtle]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(1000, 1000);
    d.turtles.push_back(turtle("far", {100, 100}, 90, 10, 60));   // heading 90: +x
    d.turtles.push_back(turtle("still", {500, 500}, 0, 10, 60));
    d.turtles.push_back(turtle("arc", {500, 200}, 90, 10, 60));
    World w(d, mode);
    w.command_turtle(0, move(2.4e107));
    w.command_turtle(1, {TurtleCommand::Kind::wait, 1e300});
    TurtleCommand arc{TurtleCommand::Kind::arc, 7.8e58 * 1e-3 / 60.0};
    arc.speed = 60.0;
    arc.rate = 60.0 / 7.8e58;
    w.command_turtle(2, arc);
    w.advance_to(2.0);
    const TurtleState far = w.turtle(0), still = w.turtle(1), bent = w.turtle(2);
    CHECK(far.pos.x == Approx(220).epsilon(1e-12));
    CHECK(far.busy);
    CHECK(still.busy);
    CHECK(still.pos.x == 500.0);
    CHECK(bent.pos.x == Approx(620).epsilon(1e-12));  // a circle of radius 7.8e58 is a line here
    CHECK(bent.busy);
  }
}
