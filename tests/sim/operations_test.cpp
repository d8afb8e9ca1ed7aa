// SPDX-License-Identifier: MIT
// Changes to a running world (World::spawn_ball, spawn_turtle, remove_*, teleport_*): they are
// checked like world-file entries, they simulate the changed body exactly, and they leave every
// other body's events bit for bit as they were.
#include <catch2/catch.hpp>

#include <cmath>
#include <set>
#include <vector>

#include "scenes.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas;
using namespace turtlegas::test;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using sim::EventKind;
using sim::Mode;
using sim::PlacementError;

namespace {

/// Two sealed chambers: a gas and two turtles on the left of a wall at x = 400, a few balls on the
/// right. What happens on the right can never reach the left.
WorldDef two_chambers() {
  WorldDef d = box(800, 400);
  d.walls.push_back(WallDef{"divider", {400, 0}, {400, 400}});
  std::mt19937_64 rng(11);
  auto uniform = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  int k = 0;
  for (int iy = 0; iy < 12; ++iy)
    for (int ix = 0; ix < 12; ++ix) {
      const double a = 2 * M_PI * uniform();
      d.balls.push_back(ball("l" + std::to_string(k++), {20.0 + 25.0 * ix, 20.0 + 25.0 * iy},
                             {60 * std::cos(a), 60 * std::sin(a)}, 4.0));
    }
  for (int i = 0; i < 6; ++i) {
    const double a = 2 * M_PI * uniform();
    d.balls.push_back(ball("r" + std::to_string(i), {450.0 + 50.0 * i, 200.0}, {50 * std::cos(a), 50 * std::sin(a)}, 4.0));
  }
  d.turtles.push_back(turtle("t0", {340, 350}, 90, 8, 40));
  d.turtles.push_back(turtle("t1", {340, 50}, 270, 8, 40));
  return d;
}
constexpr std::uint32_t kLeftBalls = 144;
constexpr std::uint32_t kLeftTurtles = 2;

/// Whether event e involves a body of the right chamber (balls from kLeftBalls on, turtles from
/// kLeftTurtles on).
bool on_the_right(const sim::Event& e) {
  auto ball_r = [](std::uint32_t i) { return i >= kLeftBalls; };
  auto turtle_r = [](std::uint32_t i) { return i >= kLeftTurtles; };
  switch (e.kind) {
    case EventKind::ball_ball: return ball_r(e.a) || ball_r(e.b);
    case EventKind::ball_wall:
    case EventKind::ball_wall_end: return ball_r(e.a);
    case EventKind::exit: return e.b == 1 ? turtle_r(e.a) : ball_r(e.a);
    case EventKind::turtle_wall:
    case EventKind::turtle_wall_end: return turtle_r(e.a);
    case EventKind::turtle_turtle: return turtle_r(e.a) || turtle_r(e.b);
    case EventKind::turtle_ball: return turtle_r(e.a) || ball_r(e.b);
    default: return true;
  }
}

/// Drives the world to t_end one control step at a time; idle turtles alternate a drive and a
/// turn. `ops` runs at boundary `at_step`.
template <class Ops>
std::vector<sim::Event> drive(sim::World& w, double t_end, std::uint64_t at_step, Ops ops) {
  std::vector<sim::Event> log;
  w.set_event_log(&log);
  std::vector<std::uint32_t> idle;
  std::vector<int> phase(64, 0);
  const double dt = w.dt();
  for (std::uint64_t k = 0; k * dt <= t_end; ++k) {
    w.advance_to(static_cast<double>(k) * dt);
    (void)w.take_turtle_contacts();
    if (k == at_step) ops(w);
    idle.clear();
    w.idle_turtles(idle);
    for (std::uint32_t t : idle) {
      if (!w.turtle_alive(t)) continue;
      const bool turn = (phase[t]++ % 2) == 1;
      w.command_turtle(t, turn ? sim::TurtleCommand{sim::TurtleCommand::Kind::turn, 1.9}
                                : sim::TurtleCommand{sim::TurtleCommand::Kind::move, 120});
    }
  }
  w.set_event_log(nullptr);
  return log;
}

std::vector<sim::Event> left_only(const std::vector<sim::Event>& log) {
  std::vector<sim::Event> out;
  for (const auto& e : log)
    if (!on_the_right(e)) out.push_back(e);
  return out;
}

bool same(const sim::Event& x, const sim::Event& y) {
  return x.t == y.t && x.kind == y.kind && x.a == y.a && x.b == y.b && x.c == y.c && x.flags == y.flags;
}

}  // namespace

TEST_CASE("a spawn, a removal and a teleport far away leave every other body's events bit for bit") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    INFO("mode " << (mode == Mode::exact ? "exact" : "step"));
    const WorldDef def = two_chambers();
    // Exact mode brings every body to the present once every max(4 N, 4096) events it serves (the
    // rebase of its internal clock, exact_clock.hpp): events elsewhere move that moment, and the
    // round-off of everybody's positions with it. This run stays before the first rebase, where
    // nothing but the operations could make a difference (docs/physics.md).
    const double t_end = mode == Mode::exact ? 7.0 : 12.0;
    sim::World plain(def, mode);
    const auto reference = drive(plain, t_end, 1u << 30, [](sim::World&) {});
    sim::World changed(def, mode);
    std::size_t new_ball = 0, new_turtle = 0;
    const auto log = drive(changed, t_end, 45, [&](sim::World& w) {
      new_ball = w.spawn_ball(ball("r-new", {700, 300}, {-35, 20}, 5.0));
      new_turtle = w.spawn_turtle(turtle("t-new", {600, 80}, 180, 8, 40));
      w.remove_ball(kLeftBalls + 2);
      w.teleport_ball(kLeftBalls + 4, {720, 100}, {10, 70});
    });
    if (mode == Mode::exact) {
      REQUIRE(plain.stats().events < 4096);
      REQUIRE(changed.stats().events < 4096);
    }
    CHECK(new_ball == def.balls.size());
    CHECK(new_turtle == def.turtles.size());
    const auto a = left_only(reference), b = left_only(log);
    REQUIRE(a.size() > 700);  // the left chamber is busy: balls, walls, turtles
    REQUIRE(a.size() == b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      INFO("event " << i << " at t = " << a[i].t << " vs " << b[i].t << " dt " << (a[i].t - b[i].t) << " kinds "
                    << int(a[i].kind) << "/" << int(b[i].kind) << " a " << a[i].a << "/" << b[i].a << " b " << a[i].b
                    << "/" << b[i].b);
      REQUIRE(same(a[i], b[i]));
    }
    // The right chamber did change: the new bodies took part, the removed ball never again.
    bool new_ball_met = false, new_turtle_met = false;
    for (const auto& e : log) {
      if (e.t < 1.5) continue;
      if ((e.kind == EventKind::ball_ball && (e.a == new_ball || e.b == new_ball)) ||
          (e.kind == EventKind::ball_wall && e.a == new_ball))
        new_ball_met = true;
      if ((e.kind == EventKind::turtle_wall || e.kind == EventKind::turtle_ball) && e.a == new_turtle)
        new_turtle_met = true;
      const bool removed = (e.kind == EventKind::ball_ball && (e.a == kLeftBalls + 2 || e.b == kLeftBalls + 2)) ||
                           (e.kind == EventKind::ball_wall && e.a == kLeftBalls + 2) ||
                           (e.kind == EventKind::turtle_ball && e.b == kLeftBalls + 2);
      CHECK_FALSE(removed);
    }
    CHECK(new_ball_met);
    CHECK(new_turtle_met);
    CHECK_FALSE(changed.ball(kLeftBalls + 2).alive);
    CHECK(changed.measure_overlap().relative < 1e-9);
  }
}

TEST_CASE("a spawned ball flies and bounces as a world-file ball does") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    WorldDef def = box(400, 400);
    def.balls.push_back(ball("a", {100, 100}, {0, 0}, 5.0));
    sim::World w(def, mode);
    w.advance_to(1.0);
    std::vector<sim::Event> log;
    w.set_event_log(&log);
    // 200 units from the ball at rest, heading for it at 50/s: contact after (200 - 10) / 50 s.
    const std::size_t b = w.spawn_ball(ball("b", {300, 100}, {-50, 0}, 5.0));
    REQUIRE(b == 1);
    CHECK(w.ball_count() == 2);
    w.advance_to(5.0);
    REQUIRE(!log.empty());
    CHECK(log[0].kind == EventKind::ball_ball);
    const double expected = 1.0 + 190.0 / 50.0;
    if (mode == Mode::exact) CHECK_THAT(log[0].t, WithinAbs(expected, 1e-12));
    else CHECK_THAT(log[0].t, WithinAbs(expected, 1e-9));
    // Equal masses, head on: the velocities are exchanged.
    CHECK_THAT(w.ball(0).vel.x, WithinAbs(-50, 1e-9));
    CHECK_THAT(w.ball(1).vel.x, WithinAbs(0, 1e-9));
    w.advance_to(8.0);
    // The left wall (x = 0): ball a, at rest at x = 100 until the contact, has 95 units to go at 50/s.
    bool wall = false;
    for (const auto& e : log)
      if (e.kind == EventKind::ball_wall && e.a == 0) {
        CHECK_THAT(e.t, WithinAbs(expected + 95.0 / 50.0, 1e-9));
        wall = true;
        break;
      }
    CHECK(wall);
  }
}

TEST_CASE("a spawned turtle drives, touches and is removed; ids are never reused") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    WorldDef def = box(400, 400);
    def.turtles.push_back(turtle("t0", {50, 50}, 0));
    def.balls.push_back(ball("a", {300, 300}, {0, 0}, 5.0));
    sim::World w(def, mode);
    w.advance_to(0.5);
    const std::size_t k = w.spawn_turtle(turtle("t1", {200, 200}, 90, 10, 30));
    REQUIRE(k == 1);
    CHECK_THAT(w.turtle(1).heading, WithinAbs(M_PI / 2, 1e-15));
    CHECK_FALSE(w.turtle(1).busy);
    w.command_turtle(1, {sim::TurtleCommand::Kind::move, 1000});
    // The right wall x = 400: contact when the centre reaches 390, after 190 / 30 s.
    w.advance_to(10.0);
    const auto contacts = w.take_turtle_contacts();
    REQUIRE(contacts.size() == 1);
    CHECK(contacts[0].turtle == 1);
    CHECK(contacts[0].kind == EventKind::turtle_wall);
    CHECK_THAT(contacts[0].t, WithinAbs(0.5 + 190.0 / 30.0, 1e-9));
    CHECK_THAT(w.turtle(1).pos.x, WithinAbs(390, 1e-9));
    // A ball spawned after the turtle: the turtle's index and state do not move.
    const std::size_t b = w.spawn_ball(ball("b", {100, 300}, {0, 0}, 5.0));
    CHECK(b == 1);
    CHECK_THAT(w.turtle(1).pos.x, WithinAbs(390, 1e-9));
    CHECK_THAT(w.turtle(0).pos.y, WithinAbs(50, 1e-12));
    w.remove_turtle(1);
    CHECK_FALSE(w.turtle_alive(1));
    CHECK_THROWS_AS(w.remove_turtle(1), std::invalid_argument);
    CHECK_THROWS_AS(w.remove_turtle(7), std::out_of_range);
    CHECK(w.spawn_turtle(turtle("t2", {390, 200}, 0)) == 2);  // where t1 was: it is gone
    w.remove_ball(0);
    CHECK(w.spawn_ball(ball("c", {300, 300}, {0, 0}, 5.0)) == 2);  // where a was: index 0 stays a's
    CHECK_FALSE(w.ball(0).alive);
    w.advance_to(12.0);
    CHECK(w.measure_overlap().relative < 1e-9);
  }
}

TEST_CASE("a teleported ball and turtle take their new course from now") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    WorldDef def = box(400, 400);
    def.balls.push_back(ball("a", {100, 100}, {10, 0}, 5.0));
    def.turtles.push_back(turtle("t0", {50, 300}, 90));
    sim::World w(def, mode);
    w.command_turtle(0, {sim::TurtleCommand::Kind::move, 1000});
    w.advance_to(2.0);
    std::vector<sim::Event> log;
    w.set_event_log(&log);
    w.teleport_ball(0, {200, 200}, {0, -40});  // the bottom wall: 195 units away
    w.teleport_turtle(0, {300, 300}, 0.0);     // heading +y, standing still
    CHECK_FALSE(w.turtle(0).busy);
    CHECK_FALSE(w.turtle(0).touched);
    CHECK_THAT(w.turtle(0).done, WithinAbs(60, 1e-9));  // 2 s at 30/s before the teleport
    CHECK_THAT(w.turtle(0).pos.x, WithinAbs(300, 0));
    w.command_turtle(0, {sim::TurtleCommand::Kind::move, 1000});  // the top wall: 90 units
    w.advance_to(10.0);
    bool ball_wall = false;
    for (const auto& e : log)
      if (e.kind == EventKind::ball_wall && e.a == 0 && !ball_wall) {
        CHECK_THAT(e.t, WithinAbs(2.0 + 195.0 / 40.0, 1e-9));
        ball_wall = true;
      }
    CHECK(ball_wall);
    const auto contacts = w.take_turtle_contacts();
    REQUIRE_FALSE(contacts.empty());
    CHECK_THAT(contacts.back().t, WithinAbs(2.0 + 90.0 / 30.0, 1e-9));
    CHECK_THAT(w.turtle(0).pos.y, WithinAbs(390, 1e-9));
  }
}

TEST_CASE("spawns and teleports are checked like world-file entries and refused with the reason") {
  WorldDef def = box(400, 400);
  def.walls.push_back(WallDef{"w-mid", {200, 100}, {200, 300}});
  def.balls.push_back(ball("a", {100, 100}, {0, 0}, 5.0));
  def.turtles.push_back(turtle("t0", {300, 300}, 0));
  sim::World w(def, Mode::exact);
  w.advance_to(1.0);
  auto refused = [&](auto&& op) -> PlacementError {
    try {
      op();
    } catch (const PlacementError& e) {
      return e;
    }
    FAIL("not refused");
    return PlacementError("");
  };
  // Overlapping ball a by 2 (centres 8 apart, radii 5 + 5).
  auto e = refused([&] { w.spawn_ball(ball("b", {108, 100}, {0, 0}, 5.0)); });
  CHECK(e.obstacle == PlacementError::Obstacle::ball);
  CHECK(e.index == 0);
  CHECK_THAT(e.depth, WithinAbs(2.0, 1e-12));
  CHECK_THAT(e.what(), Catch::Matchers::Contains("overlap ball #0 by 2"));
  // Overlapping the turtle (radius 10) by 1.
  e = refused([&] { w.spawn_ball(ball("b", {314, 300}, {0, 0}, 5.0)); });
  CHECK(e.obstacle == PlacementError::Obstacle::turtle);
  CHECK_THAT(e.depth, WithinAbs(1.0, 1e-12));
  // Overlapping the wall by 3.
  e = refused([&] { w.spawn_turtle(turtle("t1", {207, 200}, 0)); });
  CHECK(e.obstacle == PlacementError::Obstacle::wall);
  CHECK_THAT(e.what(), Catch::Matchers::Contains("wall 'w-mid'"));
  CHECK_THAT(e.depth, WithinAbs(3.0, 1e-12));
  // Outside the arena (boundary walls: the whole disc inside), bad numbers.
  CHECK_THAT(refused([&] { w.spawn_ball(ball("b", {398, 50}, {0, 0}, 5.0)); }).what(), Catch::Matchers::Contains("sticks out"));
  CHECK_THAT(refused([&] { w.spawn_ball(ball("b", {50, 50}, {0, 0}, -1.0)); }).what(), Catch::Matchers::Contains("radius"));
  CHECK_THAT(refused([&] { w.spawn_ball(ball("b", {50, 50}, {NAN, 0}, 1.0)); }).what(), Catch::Matchers::Contains("vel"));
  // A teleport onto another body, or into the wall; onto its own old place is fine.
  CHECK(refused([&] { w.teleport_ball(0, {300, 292}, {0, 0}); }).obstacle == PlacementError::Obstacle::turtle);
  CHECK(refused([&] { w.teleport_turtle(0, {195, 200}, 0); }).obstacle == PlacementError::Obstacle::wall);
  CHECK_NOTHROW(w.teleport_ball(0, {101, 100}, {1, 0}));
  // Layers: a ball that does not collide with the turtle may overlap it.
  sim::BallDef ghost = ball("g", {305, 300}, {0, 0}, 5.0);
  ghost.layers.category = 2;
  ghost.layers.mask = 2;
  CHECK_NOTHROW(w.spawn_ball(ghost));
  // Nothing changed by the refusals: two balls (a, g), one turtle.
  CHECK(w.ball_count() == 2);
  CHECK(w.turtle_count() == 1);
  CHECK_THROWS_AS(w.teleport_ball(9, {50, 50}, {0, 0}), std::out_of_range);
  // A world built without turtles keeps no turtle lists.
  sim::World gas(box(400, 400), Mode::exact);
  CHECK_THAT(refused([&] { gas.spawn_turtle(turtle("t", {50, 50}, 0)); }).what(), Catch::Matchers::Contains("without turtles"));
  CHECK_NOTHROW(gas.spawn_ball(ball("b", {50, 50}, {3, 4}, 2.0)));
}

TEST_CASE("many spawns into a running periodic gas keep it exact: no overlap, energy conserved") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    WorldDef def = random_gas(300, 0.2, 4.0, 50.0, 5, sim::Boundary::periodic);
    sim::World w(def, mode);
    std::mt19937_64 rng(99);
    auto uniform = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
    const double side = def.arena.width;
    const double e0 = w.energy();
    int spawned = 0;
    double added = 0.0;
    for (int k = 1; k <= 60; ++k) {
      w.advance_to(0.1 * k);
      const double e_before = w.energy();
      try {
        w.spawn_ball(ball("s" + std::to_string(k), {side * uniform(), side * uniform()}, {40 * uniform() - 20, 40 * uniform() - 20}, 3.0));
        ++spawned;
        added += w.energy() - e_before;
      } catch (const PlacementError&) {
      }
    }
    CHECK(spawned > 20);
    w.advance_to(10.0);
    CHECK(w.measure_overlap().relative < 1e-9);
    CHECK(w.max_contact_overlap().relative < 1e-9);
    // Elastic: the energy is the start's plus what each spawn brought, to round-off.
    CHECK_THAT(w.energy(), WithinRel(e0 + added, 1e-9));
  }
}
