// SPDX-License-Identifier: MIT
// Hard cases: each asserts the stable outcome, in both modes where the case applies to both.
#include <catch2/catch.hpp>

#include <cmath>

#include "scenes.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

namespace {

const Mode kModes[] = {Mode::exact, Mode::step};
const char* name(Mode m) { return m == Mode::exact ? "exact" : "step"; }

bool finite_state(const World& w) {
  for (std::size_t i = 0; i < w.ball_count(); ++i)
    if (!is_finite(w.ball(i).pos) || !is_finite(w.ball(i).vel)) return false;
  return true;
}

}  // namespace

TEST_CASE("a graze at exactly touching distance is not a collision", "[hard]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(100, 100);
    // Touching (distance exactly 2) with relative velocity along the tangent.
    d.balls.push_back(ball("a", {40, 50}, {0, 3}));
    d.balls.push_back(ball("b", {42, 50}, {0, -3}));
    World w(d, mode);
    w.advance_to(1.0);
    CHECK(w.stats().ball_ball == 0);
    CHECK(w.ball(0).pos.y == Approx(53));
    CHECK(w.ball(1).pos.y == Approx(47));
  }
}

TEST_CASE("touching pairs at 400 orientations, moving along their tangent, never collide in either mode",
          "[hard]") {
  // The same graze as above with rounded coordinates: each pair starts at a distance of at least
  // 1 in doubles (the loader's test), its relative velocity perpendicular to the line of centres
  // up to rounding. A rounding-sized approach must not count as a collision in step mode, which
  // moves every ball by x + v dt at each step, any more than in exact mode. (Filed as a step-mode
  // bug; not reproduced in the split engine, kept as the contract's guard.)
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(420, 420);
    d.dt = 0.1;
    std::uint64_t state = 2;
    auto uniform = [&state] {  // a fixed LCG so the test needs no <random> distribution's behaviour
      state = state * 6364136223846793005ULL + 1442695040888963407ULL;
      return static_cast<double>(state >> 11) * 0x1.0p-53;
    };
    for (int n = 0; n < 400;) {
      const double th = 2 * 3.141592653589793 * uniform();
      const int row = n / 20, col = n % 20;
      const Vec2 o{10 + row * 20 + uniform(), 10 + col * 20 + uniform()};
      const Vec2 p{o.x + std::cos(th), o.y + std::sin(th)};
      if (norm2(p - o) < 1.0) continue;
      const Vec2 v{-2 * std::sin(th), 2 * std::cos(th)};
      BallDef a = ball("a" + std::to_string(n), o, v), b = ball("b" + std::to_string(n), p, {-v.x, -v.y});
      a.radius = b.radius = 0.5;
      d.balls.push_back(a);
      d.balls.push_back(b);
      ++n;
    }
    World w(d, mode);
    w.advance_to(0.5);
    CHECK(w.stats().ball_ball == 0);
  }
}

TEST_CASE("a ball sliding along a wall at exactly its radius never touches it", "[hard]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(200, 100, Boundary::none);
    d.walls.push_back({"floor", {0, 10}, {200, 10}});
    d.balls.push_back(ball("s", {5, 11}, {7, 0}));
    World w(d, mode);
    w.advance_to(20.0);
    CHECK(w.stats().collisions() == 0);
    CHECK(w.ball(0).pos.x == Approx(145));
    CHECK(w.ball(0).pos.y == 11.0);
  }
}

TEST_CASE("Newton's cradle of five touching balls", "[hard]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(200, 100);
    d.balls.push_back(ball("b0", {20, 50}, {3, 0}));
    for (int k = 1; k <= 4; ++k) d.balls.push_back(ball("b" + std::to_string(k), {30.0 + 2 * (k - 1), 50}, {0, 0}));
    World w(d, mode);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.advance_to(10.0 / 3.0 + 1.0);
    // Contact at t = 8/3; the impulse passes down the row as binary collisions at that instant,
    // in a fixed order, and only the last ball moves off.
    REQUIRE(log.size() >= 4);
    for (int k = 0; k < 4; ++k) {
      CHECK(log[k].kind == EventKind::ball_ball);
      CHECK(std::min(log[k].a, log[k].b) == static_cast<unsigned>(k));
      CHECK(std::max(log[k].a, log[k].b) == static_cast<unsigned>(k + 1));
      CHECK(log[k].t == Approx(8.0 / 3.0).epsilon(1e-12));
    }
    CHECK(w.stats().ball_ball == 4);
    for (int k = 0; k < 4; ++k) CHECK(norm(w.ball(k).vel) <= 1e-12);
    CHECK(w.ball(4).vel.x == Approx(3).epsilon(1e-12));
  }
}

TEST_CASE("a ball aimed exactly at a wall end", "[hard]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    SECTION("along the wall's line: a wall-end contact, straight back") {
      WorldDef d = box(100, 100);
      d.walls.push_back({"w", {50, 50}, {70, 50}});
      d.balls.push_back(ball("a", {30, 50}, {4, 0}));
      World w(d, mode);
      std::vector<Event> log;
      w.set_event_log(&log);
      w.advance_to(6.0);
      REQUIRE(log.size() == 1);
      CHECK(log[0].kind == EventKind::ball_wall_end);
      CHECK(log[0].t == Approx(19.0 / 4.0).epsilon(1e-12));
      CHECK(w.ball(0).vel.x == Approx(-4));
      CHECK(std::abs(w.ball(0).vel.y) <= 1e-12);
    }
    SECTION("square on, contact foot exactly at the end: a wall contact (ends included)") {
      WorldDef d = box(100, 100);
      d.walls.push_back({"w", {50, 50}, {70, 50}});
      d.balls.push_back(ball("a", {50, 30}, {0, 4}));
      World w(d, mode);
      std::vector<Event> log;
      w.set_event_log(&log);
      w.advance_to(6.0);
      REQUIRE(log.size() == 1);
      CHECK(log[0].kind == EventKind::ball_wall);
      CHECK(w.ball(0).vel.y == Approx(-4));
    }
  }
}

TEST_CASE("concave corners of 90 and 30 degrees", "[hard]") {
  for (double angle : {90.0, 30.0}) {
    for (Mode mode : kModes) {
      INFO(name(mode) << " corner " << angle);
      WorldDef d = box(400, 400, Boundary::none);
      const double a = angle * M_PI / 180.0;
      const Vec2 apex{100, 200};
      // Two walls from the apex, symmetric about the +x axis.
      d.walls.push_back({"upper", apex, apex + 250.0 * Vec2{std::cos(a / 2), std::sin(a / 2)}});
      d.walls.push_back({"lower", apex, apex + 250.0 * Vec2{std::cos(a / 2), -std::sin(a / 2)}});
      // A ball flying into the corner slightly off the bisector.
      d.balls.push_back(ball("b", {300, 203}, {-10, -0.7}, 2.0));
      World w(d, mode);
      const double e0 = w.energy();
      w.advance_to(45.0);  // in, back out, and still inside the arena
      CHECK(finite_state(w));
      CHECK(w.measure_overlap().relative <= 1e-9);
      CHECK(w.energy() == Approx(e0).epsilon(1e-13));
      CHECK(w.stats().ball_wall >= 2);
      CHECK(w.stats().ball_wall <= 8);  // a wedge of angle a returns a ray after about pi/a bounces
      // It comes back out of the wedge, heading away from the apex.
      CHECK(w.ball(0).vel.x > 0);
    }
  }
}

TEST_CASE("coordinates near 1e6 behave like coordinates near 0", "[hard]") {
  for (Mode mode : kModes) {
    INFO(name(mode));
    const WorldDef near0 = random_gas(50, 0.2, 1.0, 5.0, 51, Boundary::none);
    WorldDef far = near0;
    // Shift everything by 1e6: an open arena cannot move, so use interior walls for the box.
    const Vec2 shift{1e6, 1e6};
    far.arena.width = near0.arena.width + 2e6;
    far.arena.height = near0.arena.height + 2e6;
    far.arena.cell = 1e5;  // the table need not be fine out there; only the discs matter
    WorldDef base = near0;
    const double s = near0.arena.width;
    for (WorldDef* w : {&base, &far}) {
      const Vec2 o = w == &far ? shift : Vec2{};
      w->walls = {{"b", o, o + Vec2{s, 0}}, {"r", o + Vec2{s, 0}, o + Vec2{s, s}}, {"t", o + Vec2{s, s}, o + Vec2{0, s}},
                  {"l", o + Vec2{0, s}, o}};
      for (auto& b : w->balls) b.pos = b.pos + o;
    }
    World w0(base, mode), w1(far, mode);
    w0.advance_to(3.0);
    w1.advance_to(3.0);
    CHECK(w1.stats().collisions() == w0.stats().collisions());
    CHECK(w0.stats().collisions() > 30);
    CHECK(w1.measure_overlap().relative <= 1e-9);
    CHECK(w1.max_contact_overlap().relative <= 1e-9);
    CHECK(finite_state(w1));
    for (std::size_t i = 0; i < base.balls.size(); ++i) {
      // Positions out there carry 1e6 * eps ~ 1e-10 of absolute round-off per operation.
      CHECK((w1.ball(i).pos - shift).x == Approx(w0.ball(i).pos.x).margin(1e-6));
      CHECK((w1.ball(i).pos - shift).y == Approx(w0.ball(i).pos.y).margin(1e-6));
    }
  }
}

TEST_CASE("extreme speeds: 1e-9 and 1e8", "[hard]") {
  for (double speed : {1e-9, 1e8}) {
    for (Mode mode : kModes) {
      INFO(name(mode) << " speed " << speed);
      WorldDef d = random_gas(40, 0.2, 1.0, speed, 61);
      // About 40 mean free times either way; step mode's dt follows the speed.
      const double T = 40.0 * d.arena.width / speed;
      d.dt = d.arena.width / speed / 30.0;
      World w(d, mode);
      const double e0 = w.energy();
      w.advance_to(T);
      CHECK(finite_state(w));
      CHECK(w.stats().collisions() > 100);
      CHECK(w.measure_overlap().relative <= 1e-9);
      CHECK(w.energy() == Approx(e0).epsilon(1e-12));
      CHECK(w.stats().exits == 0);
    }
  }
}

TEST_CASE("an inelastic ball comes to rest on a floor under gravity", "[hard][inelastic]") {
  for (double e : {0.5, 0.0}) {
    INFO("restitution " << e);
    WorldDef d = box(100, 100);
    d.effects.gravity = {0, -9.8};
    d.effects.restitution = e;
    d.balls.push_back(ball("drop", {50, 30}, {1.5, 0}, 1.0));
    World w(d, Mode::exact);
    w.advance_to(20.0);
    const BallState s = w.ball(0);
    const double tc = d.effects.tc;
    // Resting: hops no higher than g tc^2 / 8 and no faster than g tc / 2 (the rest threshold).
    CHECK(s.pos.y - 1.0 >= -1e-12);
    CHECK(s.pos.y - 1.0 <= 9.8 * tc * tc / 8 + 1e-12);
    CHECK(std::abs(s.vel.y) <= 9.8 * tc / 2 * (1 + 1e-9));
    CHECK(w.measure_overlap().relative <= 1e-9);
    // The run terminated: the rest hops cost at most one collision per tc.
    CHECK(w.stats().collisions() <= 20.0 / tc + 1000);
    CHECK(finite_state(w));
  }
  SECTION("step mode settles within a step's fall") {
    WorldDef d = box(100, 100);
    d.effects.gravity = {0, -9.8};
    d.effects.restitution = 0.5;
    d.balls.push_back(ball("drop", {50, 30}, {0, 0}, 1.0));
    World w(d, Mode::step);
    w.advance_to(20.0);
    const BallState s = w.ball(0);
    CHECK(s.pos.y - 1.0 >= -1e-12);
    CHECK(s.pos.y - 1.0 <= 9.8 * d.dt * d.dt);
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}

TEST_CASE("an elastic ball resting on a floor stays on it", "[hard]") {
  WorldDef d = box(100, 100);
  d.effects.gravity = {0, -9.8};
  d.balls.push_back(ball("rest", {50, 1}, {0, 0}, 1.0));
  World w(d, Mode::exact);
  w.advance_to(5.0);
  CHECK(w.ball(0).pos.y >= 1.0 - 1e-12);
  CHECK(w.ball(0).pos.y <= 1.0 + 9.8 * d.effects.tc * d.effects.tc / 8 + 1e-12);
}

TEST_CASE("a pair that has just collided never re-collides through round-off", "[hard]") {
  // Nearly tangential contacts leave a normal velocity of a few ulps; with straight relative
  // motion the pair must not meet again.
  for (Mode mode : kModes) {
    INFO(name(mode));
    WorldDef d = box(1000, 1000);
    for (int k = 0; k < 50; ++k) {
      const double y = 20.0 * k + 10;
      d.balls.push_back(ball("a" + std::to_string(k), {100, y}, {5, 0}));
      // Offset so that the centres pass at 2 - 1e-13 * k: a graze by a hair.
      d.balls.push_back(ball("b" + std::to_string(k), {200, y + 2.0 - 1e-13 * (k + 1)}, {-5, 0}));
    }
    World w(d, mode);
    w.advance_to(12.0);
    CHECK(w.stats().ball_ball == 50);
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}

TEST_CASE("a ball thrown up past the end of a shelf lands on it, whatever the cell size", "[hard][gravity]") {
  // It rises past the shelf's end beyond the line, so its first prediction for the shelf's lower
  // face finds nothing; the landing on the upper face must still be found (it once was not, with
  // cells so large that no cell crossing made the ball look at the shelf again).
  for (double cell : {2.0, 5.0, 20.0}) {
    for (Mode mode : {Mode::exact, Mode::step}) {
      INFO("cell " << cell << (mode == Mode::exact ? " exact" : " step"));
      WorldDef d = box(40, 40, Boundary::none);
      d.arena.cell = cell;
      d.dt = 0.01;
      d.walls.push_back({"shelf", {3, 10}, {13, 10}});
      d.balls.push_back(ball("b", {16.5, 8}, {-4, 8}, 0.5));
      d.effects.gravity = {0, -9.81};
      World w(d, mode);
      std::vector<Event> log;
      w.set_event_log(&log);
      w.advance_to(1.5);
      REQUIRE(log.size() >= 1);
      CHECK(log[0].kind == EventKind::ball_wall);
      // Step mode kicks the velocity between steps (the memo's algorithm): a polygon, not the
      // parabola, so its landing comes a little later (1.225 s with dt = 0.01).
      if (mode == Mode::exact) CHECK(log[0].t == Approx((8 + std::sqrt(64 - 49.05)) / 9.81).epsilon(1e-12));
      else CHECK(log[0].t == Approx((8 + std::sqrt(64 - 49.05)) / 9.81).epsilon(0.02));
      CHECK(w.ball(0).pos.y > 10.5 - 1e-9);
    }
  }
}
