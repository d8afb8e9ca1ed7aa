// SPDX-License-Identifier: MIT
// Collision layers: walls "not really there" for some bodies, invisible turtles.
#include <catch2/catch.hpp>

#include <cmath>

#include "scenes.hpp"
#include "turtlegas/sim/reference.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

namespace {
constexpr std::uint32_t kWalls = 1u << 1, kBalls = 1u << 2, kGhost = 1u << 3, kBlind = 1u << 4;
const Mode kModes[] = {Mode::exact, Mode::step};
}  // namespace

TEST_CASE("a wall that is not there for one ball stops the other", "[layers]") {
  for (Mode mode : kModes) {
    INFO((mode == Mode::exact ? "exact" : "step"));
    WorldDef d = box(300, 100);
    WallDef w{"glass", {150, 0}, {150, 100}};
    w.layers = {kWalls, ~kBlind};  // everything collides with it, except category "blind"
    d.walls.push_back(w);
    BallDef seeing = ball("seeing", {100, 30}, {10, 0});
    BallDef blind = ball("blind", {100, 70}, {10, 0});
    blind.layers = {kBlind, 0xffffffffu};
    d.balls = {seeing, blind};
    World world(d, mode);
    world.advance_to(8.0);
    CHECK(world.ball(0).vel.x == Approx(-10));  // bounced at x = 149 after 4.9 s
    CHECK(world.ball(1).pos.x == Approx(180));  // straight through
    CHECK(world.stats().ball_wall == 1);
    CHECK(world.measure_overlap().relative <= 1e-9);
  }
}

TEST_CASE("an invisible turtle passes through balls and turtles but not walls", "[layers]") {
  for (Mode mode : kModes) {
    INFO((mode == Mode::exact ? "exact" : "step"));
    WorldDef d = box(400, 200);
    d.arena.boundary = Boundary::none;
    WallDef east{"east", {300, 0}, {300, 200}};
    east.layers = {kWalls, 0xffffffffu};
    d.walls.push_back(east);
    TurtleDef ghost;
    ghost.id = "ghost";
    ghost.pos = {50, 100};
    ghost.heading = M_PI / 2;  // +x
    ghost.radius = 10;
    ghost.speed = 50;
    ghost.layers = {kGhost, kWalls};  // it meets walls only
    TurtleDef solid = ghost;
    solid.id = "solid";
    solid.pos = {150, 100};
    solid.layers = {1u, 0xffffffffu};
    d.turtles = {ghost, solid};
    d.balls.push_back(ball("b", {100, 100}, {0, 0}, 3));
    World w(d, mode);
    w.command_turtle(0, {TurtleCommand::Kind::move, 1000});
    w.advance_to(10.0);
    // It crossed the ball (x = 100) and the other turtle (x = 150) and stopped at the wall.
    CHECK(w.turtle(0).pos.x == Approx(290));
    CHECK(w.turtle(0).touched);
    CHECK(w.stats().turtle_ball == 0);
    CHECK(w.stats().turtle_turtle == 0);
    CHECK(w.stats().turtle_wall == 1);
    CHECK(w.ball(0).vel.x == 0.0);
    const auto contacts = w.take_turtle_contacts();
    REQUIRE(contacts.size() == 1);
    CHECK(contacts[0].kind == EventKind::turtle_wall);
  }
}

TEST_CASE("layered gas matches the brute-force reference", "[layers][reference]") {
  WorldDef d = random_gas(40, 0.2, 1.0, 5.0, 71);
  // Half the balls cannot see each other's half; a baffle is there only for the first half.
  for (std::size_t i = 0; i < d.balls.size(); ++i)
    d.balls[i].layers = i % 2 ? Layers{kBalls, kBalls | 1u} : Layers{kBlind, kBlind | 1u | kWalls};
  const double s = d.arena.width;
  WallDef baffle{"baffle", {0.5 * s, 0.2 * s}, {0.5 * s + 0.5, 0.8 * s}};
  baffle.layers = {kWalls, kBlind};
  d.walls.push_back(baffle);
  std::vector<BallDef> keep;
  for (const auto& b : d.balls)
    if (std::abs(b.pos.x - 0.5 * s) > 2.5) keep.push_back(b);
  d.balls = keep;
  World w(d, Mode::exact);
  std::vector<Event> log;
  w.set_event_log(&log);
  w.advance_to(4.0);
  const auto ref = reference::events(d, 4.0);
  REQUIRE(ref.size() > 50);
  REQUIRE(log.size() == ref.size());
  for (std::size_t k = 0; k < ref.size(); ++k) {
    auto a = log[k], b = ref[k];
    if (a.kind == EventKind::ball_ball && a.a > a.b) std::swap(a.a, a.b);
    if (b.kind == EventKind::ball_ball && b.a > b.b) std::swap(b.a, b.b);
    INFO("event " << k);
    REQUIRE(a.kind == b.kind);
    REQUIRE(a.a == b.a);
    REQUIRE(a.b == b.b);
    REQUIRE(a.t == Approx(b.t).margin(1e-9));
  }
  CHECK(w.measure_overlap().relative <= 1e-9);
}

TEST_CASE("objects whose layers do not meet may start overlapping; others may not", "[layers][validate]") {
  WorldDef d = box(100, 100);
  BallDef a = ball("a", {50, 50}, {0, 0}, 5);
  BallDef b = ball("b", {53, 50}, {0, 0}, 5);
  d.balls = {a, b};
  CHECK(validate(d).has_value());
  d.balls[1].layers = {kGhost, kGhost};
  CHECK_FALSE(validate(d).has_value());
  CHECK_NOTHROW(World(d, Mode::exact));
  // A wall may be laid through a body that passes through it, and not through one that does not.
  World w(d, Mode::exact);
  WallDef through{"through", {53, 0}, {53, 100}};
  through.layers = {1u, ~kGhost};
  CHECK_THROWS_WITH(w.add_wall(through), Catch::Contains("would overlap a ball"));
  through.layers = {kGhost, kGhost};  // there only for the ghost, which it overlaps
  CHECK_THROWS(w.add_wall(through));
  through.layers = {kWalls, 1u};  // there only for category 1: ball a, whose centre is 3 away
  CHECK_THROWS(w.add_wall(through));
  WallDef clear{"clear", {53, 0}, {53, 100}};
  clear.layers = {kWalls, 0u};  // there for nobody
  CHECK_NOTHROW(w.add_wall(clear));
}
