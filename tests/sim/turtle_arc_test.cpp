// SPDX-License-Identifier: MIT
// Turtles on arcs (TurtleCommand::Kind::arc): the times of contact on a circle against closed
// forms (wall, wall end, a disc at rest, a turtle at rest) and against an independent root search
// (a moving disc), tangency, a contact 1e-9 of a radius deep, and laps that end where they began.
#include <catch2/catch.hpp>

#include <cmath>

#include "scenes.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

namespace {

const Mode kModes[] = {Mode::exact, Mode::step};
const char* name(Mode m) { return m == Mode::exact ? "exact" : "step"; }

/// Drive at `speed` while turning at `rate` rad/s (positive clockwise) for `seconds`.
TurtleCommand arc(double speed, double rate, double seconds, double angle = std::nan("")) {
  TurtleCommand c;
  c.kind = TurtleCommand::Kind::arc;
  c.amount = seconds;
  c.speed = speed;
  c.rate = rate;
  c.angle = angle;
  return c;
}

// The scene of most cases: a turtle of radius 10 at (200, 200) heading 0 (+y), driving at 30 with
// rate 0.3 rad/s clockwise: a circle of radius R = 100 about C = (300, 200), its centre at
// C + R (-cos phi, sin phi) after turning phi = 0.3 t.
constexpr double kV = 30.0, kW = 0.3, kR = 100.0;
const Vec2 kC{300.0, 200.0};

Vec2 on_circle(double phi) { return {kC.x - kR * std::cos(phi), kC.y + kR * std::sin(phi)}; }

/// The first phi in (0, pi/2] at which the centre comes within `dist` of the point p = C + (0, d):
/// |x - p|^2 = R^2 + d^2 - 2 R d sin(phi) = dist^2.
double phi_to_point(double d, double dist) { return std::asin((kR * kR + d * d - dist * dist) / (2.0 * kR * d)); }

WorldDef scene() {
  WorldDef d = box(800, 800);
  d.turtles.push_back(turtle("t", {200, 200}, 0, 10, kV));
  return d;
}

void check_stop(World& w, double phi, EventKind kind) {
  const TurtleState s = w.turtle(0);
  const Vec2 x = on_circle(phi);
  CHECK(s.touched);
  CHECK_FALSE(s.busy);
  CHECK(std::abs(s.pos.x - x.x) <= 1e-9);
  CHECK(std::abs(s.pos.y - x.y) <= 1e-9);
  CHECK(std::abs(s.heading - phi) <= 1e-9);
  CHECK(std::abs(s.done - kV * phi / kW) <= 1e-9);  // the distance along the arc
  CHECK(norm(s.vel) == 0.0);
  const auto contacts = w.take_turtle_contacts();
  REQUIRE(contacts.size() == 1);
  CHECK(contacts[0].kind == kind);
  CHECK(std::abs(contacts[0].t - phi / kW) <= 1e-9);
  CHECK(w.measure_overlap().relative <= 1e-9);
}

}  // namespace

TEST_CASE("an arc stops dead at its contact with a wall, at the closed-form time", "[turtle][arc]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = scene();
    d.walls.push_back({"top", {0, 280}, {800, 280}});  // the centre reaches y = 270 at sin(phi) = 0.7
    World w(d, mode);
    w.command_turtle(0, arc(kV, kW, 10.0));
    w.advance_to(12.0);
    check_stop(w, std::asin(0.7), EventKind::turtle_wall);
  }
}

TEST_CASE("an arc meets a wall end at the closed-form time", "[turtle][arc]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = scene();
    d.walls.push_back({"post", {300, 305}, {300, 500}});  // its lower end 105 above C
    World w(d, mode);
    w.command_turtle(0, arc(kV, kW, 10.0));
    w.advance_to(12.0);
    check_stop(w, phi_to_point(105, 10), EventKind::turtle_wall_end);
  }
}

TEST_CASE("an arc meets a disc at rest and a turtle at rest at the closed-form times", "[turtle][arc]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    {
      WorldDef d = scene();
      d.balls.push_back(ball("b", {300, 310}, {0, 0}, 5));  // 110 above C, contact at 15
      World w(d, mode);
      w.command_turtle(0, arc(kV, kW, 10.0));
      w.advance_to(12.0);
      check_stop(w, phi_to_point(110, 15), EventKind::turtle_ball);
      CHECK(norm(w.ball(0).vel) == 0.0);  // the turtle stopped dead before it could push it
    }
    {
      WorldDef d = scene();
      d.turtles.push_back(turtle("u", {300, 312}, 0, 8, kV));  // 112 above C, contact at 18
      World w(d, mode);
      w.command_turtle(0, arc(kV, kW, 10.0));
      w.advance_to(12.0);
      const TurtleState s = w.turtle(0);
      const double phi = phi_to_point(112, 18);
      CHECK(s.touched);
      CHECK(std::abs(s.pos.x - on_circle(phi).x) <= 1e-9);
      CHECK(std::abs(s.pos.y - on_circle(phi).y) <= 1e-9);
      const auto contacts = w.take_turtle_contacts();
      REQUIRE(contacts.size() == 2);  // both turtles are told
      CHECK(std::abs(contacts[0].t - phi / kW) <= 1e-9);
    }
  }
}

TEST_CASE("an arc meets a moving disc when an independent root search says", "[turtle][arc]") {
  // The ball falls straight down x = 320 at 20 units/s: gap(t) = |x(t) - b(t)|^2 - 15^2, its first
  // root bracketed on a fine grid and bisected to adjacent doubles (the oracle; the engine never
  // samples).
  const Vec2 b0{320, 420}, u{0, -20};
  auto gap = [&](double t) {
    const Vec2 x = on_circle(kW * t);
    const Vec2 b = b0 + t * u;
    const Vec2 r = x - b;
    return dot(r, r) - 225.0;
  };
  double lo = 0.0, hi = 0.0;
  for (double t = 0.0; t < 10.0; t += 1e-4)
    if (gap(t + 1e-4) <= 0.0) {
      lo = t;
      hi = t + 1e-4;
      break;
    }
  REQUIRE(hi > 0.0);
  while (true) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (gap(mid) <= 0.0 ? hi : lo) = mid;
  }
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = scene();
    d.balls.push_back(ball("b", b0, u, 5));
    World w(d, mode);
    w.command_turtle(0, arc(kV, kW, 10.0));
    w.advance_to(hi + 1e-3);
    const auto contacts = w.take_turtle_contacts();
    REQUIRE(contacts.size() == 1);
    CHECK(contacts[0].kind == EventKind::turtle_ball);
    CHECK(std::abs(contacts[0].t - hi) <= 1e-9);
    const TurtleState s = w.turtle(0);
    CHECK(std::abs(s.pos.x - on_circle(kW * hi).x) <= 1e-9);
    CHECK(std::abs(s.pos.y - on_circle(kW * hi).y) <= 1e-9);
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}

TEST_CASE("an arc tangent to a wall passes it; one 1e-9 of a radius into it stops there", "[turtle][arc]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    {
      // The circle's top is y = 300: a wall at 310 is touched by the disc's edge only there.
      WorldDef d = scene();
      d.walls.push_back({"top", {0, 310}, {800, 310}});
      World w(d, mode);
      const double half = M_PI / kW;  // half a lap: from (200, 200) over the top to (400, 200)
      w.command_turtle(0, arc(kV, kW, half, M_PI));
      w.advance_to(half + 1.0);
      const TurtleState s = w.turtle(0);
      CHECK_FALSE(s.touched);
      CHECK(std::abs(s.pos.x - 400.0) <= 1e-9);
      CHECK(std::abs(s.pos.y - 200.0) <= 1e-9);
      CHECK(std::abs(s.heading - M_PI) <= 1e-12);
      CHECK(w.take_turtle_contacts().empty());
    }
    {
      WorldDef d = scene();
      d.walls.push_back({"top", {0, 310 - 1e-8}, {800, 310 - 1e-8}});
      World w(d, mode);
      w.command_turtle(0, arc(kV, kW, M_PI / kW, M_PI));
      w.advance_to(M_PI / kW + 1.0);
      const TurtleState s = w.turtle(0);
      CHECK(s.touched);
      // Contact where the centre is 1e-8 below the top: cos(phi - pi/2) = 1 - 1e-10.
      const double phi = M_PI / 2 - std::acos(1.0 - 1e-10);
      CHECK(std::abs(s.heading - phi) <= 1e-4);
      CHECK(s.pos.y + 10.0 <= 310 - 1e-8 + 1e-9 * 10.0);
      CHECK(w.measure_overlap().relative <= 1e-9);
    }
  }
}

TEST_CASE("arcs to the left, backwards, and a turtle's arc among others' straight strokes", "[turtle][arc]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    // Counter-clockwise (rate < 0) the centre is on the left: C' = (100, 200); a quarter turn
    // ends at (100, 300) heading -90 degrees.
    WorldDef d = scene();
    World w(d, mode);
    w.command_turtle(0, arc(kV, -kW, (M_PI / 2) / kW, -M_PI / 2));
    w.advance_to(6.0);
    TurtleState s = w.turtle(0);
    CHECK_FALSE(s.touched);
    CHECK(std::abs(s.pos.x - 100.0) <= 1e-9);
    CHECK(std::abs(s.pos.y - 300.0) <= 1e-9);
    CHECK(std::abs(s.heading + M_PI / 2) <= 1e-12);
    CHECK(std::abs(s.done - kV * (M_PI / 2) / kW) <= 1e-9);
    // Backwards and clockwise: the heading turns right while the disc reverses, so it circles
    // C'' = (100 - 100, 300) ... a quarter ends at (0 + 100, 300 - 100) rotated: check against the
    // flight's closed form, x0 + sin(phi)/w v0 + (1 - cos phi)/w J(v0), v0 = -30 (sin h, cos h).
    const double h = s.heading;
    const Vec2 v0{-kV * std::sin(h), -kV * std::cos(h)};
    const Vec2 x0 = s.pos;
    w.command_turtle(0, arc(-kV, kW, 1.0));
    w.advance_to(7.5);
    s = w.turtle(0);
    const Vec2 x1 = x0 + (std::sin(kW) / kW) * v0 + ((1 - std::cos(kW)) / kW) * Vec2{v0.y, -v0.x};
    CHECK(std::abs(s.pos.x - x1.x) <= 1e-9);
    CHECK(std::abs(s.pos.y - x1.y) <= 1e-9);
    CHECK(std::abs(s.heading - (h + kW)) <= 1e-12);
  }
}

TEST_CASE("a turtle driving full circles returns to its start after 10^4 laps", "[turtle][arc]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = scene();
    d.dt = 1.0 / 30;
    World w(d, mode);
    const double lap = 2 * M_PI / kW;
    double t = 0.0;
    for (int k = 0; k < 10000; ++k) {
      // (Each arc runs to its end before the next: a command given at its very end would cut it.)
      w.command_turtle(0, arc(kV, kW, lap, 2 * M_PI));
      t += lap + 0.01;
      w.advance_to(t);
    }
    w.advance_to(t + 1.0);
    TurtleState s = w.turtle(0);
    CHECK_FALSE(s.busy);
    CHECK_FALSE(s.touched);
    CHECK(std::abs(s.pos.x - 200.0) <= 1e-12 * kR);
    CHECK(std::abs(s.pos.y - 200.0) <= 1e-12 * kR);
    CHECK(std::abs(std::remainder(s.heading, 2 * M_PI)) <= 1e-12);
  }
}

TEST_CASE("a circle driven in quarter arcs closes to round-off after 10^4 laps", "[turtle][arc]") {
  WorldDef d = scene();
  World w(d, Mode::exact);
  const double quarter = (M_PI / 2) / kW;
  double t = 0.0;
  for (int k = 0; k < 40000; ++k) {
    w.command_turtle(0, arc(kV, kW, quarter, M_PI / 2));
    t += quarter + 0.01;
    w.advance_to(t);
  }
  const TurtleState s = w.turtle(0);
  CHECK_FALSE(s.touched);
  INFO("drift " << s.pos.x - 200.0 << ", " << s.pos.y - 200.0);
  CHECK(std::abs(s.pos.x - 200.0) <= 1e-9 * kR);
  CHECK(std::abs(s.pos.y - 200.0) <= 1e-9 * kR);
}
