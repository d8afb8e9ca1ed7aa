// SPDX-License-Identifier: MIT
// The scene checks the engine used to make on its own at construction, now in validate(): each
// names the wall, the field (so that the world-file loader can print the JSON path) and the fix.
#include <optional>
#include <stdexcept>
#include <string>

#include <catch2/catch.hpp>

#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"

using namespace turtlegas::sim;

namespace {

WorldDef periodic_box() {
  WorldDef d;
  d.arena.width = 100;
  d.arena.height = 100;
  d.arena.boundary = Boundary::periodic;
  BallDef b;
  b.id = "b";
  b.pos = {50, 50};
  b.radius = 1;
  d.balls.push_back(b);
  return d;
}

WallDef wall(std::string id, Vec2 from, Vec2 to) {
  WallDef w;
  w.id = std::move(id);
  w.from = from;
  w.to = to;
  return w;
}

std::string construction_error(const WorldDef& d) {
  try {
    World w(d, Mode::exact);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("a wall reaching outside a periodic arena is a problem of that end", "[validate][periodic]") {
  WorldDef d = periodic_box();
  d.walls.push_back(wall("w0", {10, 10}, {20, 10}));   // inside, on no edge
  d.walls.push_back(wall("w1", {10, 20}, {120, 20}));  // its second end is out
  auto p = validate(d);
  REQUIRE(p);
  CHECK(p->where == DefProblem::Where::wall);
  CHECK(p->index == 1);
  CHECK(p->field == "to");
  CHECK(p->message ==
        "wall 'w1' reaches outside a periodic arena (its end to [120, 20] is not in [0, 100] x [0, 100]); keep walls "
        "inside it");
  // The engine reports the same message, through validate().
  CHECK(construction_error(d) == p->message);

  d.walls[1] = wall("", {-0.5, 20}, {50, 20});  // anonymous, the first end out
  p = validate(d);
  REQUIRE(p);
  CHECK(p->index == 1);
  CHECK(p->field == "from");
  CHECK(p->message ==
        "wall #1 reaches outside a periodic arena (its end from [-0.5, 20] is not in [0, 100] x [0, 100]); keep walls "
        "inside it");

  // On the edges is inside; outside an arena that is not periodic is allowed.
  d.walls[1] = wall("edge", {0, 0}, {100, 0});
  CHECK_FALSE(validate(d));
  d.walls[1] = wall("w1", {10, 20}, {120, 20});
  d.arena.boundary = Boundary::none;
  CHECK_FALSE(validate(d));
}

TEST_CASE("a moving wall in a periodic arena is a problem of its keys", "[validate][periodic]") {
  WorldDef d = periodic_box();
  WallDef w = wall("door", {10, 10}, {20, 10});
  w.keys.push_back({2.0, {10, 30}, {20, 30}});
  d.walls.push_back(w);
  const auto p = validate(d);
  REQUIRE(p);
  CHECK(p->where == DefProblem::Where::wall);
  CHECK(p->index == 0);
  CHECK(p->field == "keys");
  CHECK(p->message ==
        "wall 'door' moves: moving walls are not supported in a periodic arena yet; remove its keys or use boundary "
        "\"walls\" or \"none\"");
  CHECK(construction_error(d) == p->message);
  d.arena.boundary = Boundary::walls;
  CHECK_FALSE(validate(d));
}

TEST_CASE("visibility times must increase and be >= 0", "[validate][visibility]") {
  WorldDef d = periodic_box();
  d.arena.boundary = Boundary::none;
  d.walls.push_back(wall("gate", {10, 10}, {20, 10}));
  d.walls[0].visibility = {{0.0, false}, {1.0, true}, {1.0, false}};
  auto p = validate(d);
  REQUIRE(p);
  CHECK(p->where == DefProblem::Where::wall);
  CHECK(p->index == 0);
  CHECK(p->field == "visible");  // the world file's key, so that the loader's path is /walls/0/visible
  CHECK(p->message == "wall 'gate' visibility key 2: times must increase and be >= 0 (got 1 after 1)");
  CHECK(construction_error(d) == p->message);

  d.walls[0].visibility = {{-0.25, false}};
  p = validate(d);
  REQUIRE(p);
  CHECK(p->message == "wall 'gate' visibility key 0: times must increase and be >= 0 (got -0.25)");

  d.walls[0].visibility = {{0.0, false}, {0.5, true}};  // from 0 on is allowed
  CHECK_FALSE(validate(d));
  World w(d, Mode::exact);
  CHECK(w.walls().size() == 1);
}

TEST_CASE("a wall added while a periodic world runs must lie inside it too", "[world][periodic]") {
  World w(periodic_box(), Mode::exact);
  try {
    w.add_wall(wall("late", {90, 10}, {110, 10}));
    FAIL("no error");
  } catch (const std::invalid_argument& e) {
    CHECK(std::string(e.what()) == "wall 'late' reaches outside a periodic arena; keep walls inside it");
  }
  CHECK(w.add_wall(wall("fits", {90, 10}, {100, 10})) == 0);
}

TEST_CASE("a speed the times of impact cannot square in this arena is a problem of that body", "[validate][hard]") {
  // Two discs in a 1000 x 1000 box, one at 1e160 units/s off-centre towards the other: the pair's
  // time of impact squares (r x v) ~ 1e162 to infinity, the root is NaN and the fast disc passed
  // through the still one without a collision (0 ball-ball, exit 0) before this check.
  WorldDef d;
  d.arena.width = 1000;
  d.arena.height = 1000;
  d.arena.boundary = Boundary::walls;
  BallDef fast, still;
  fast.id = "fast";
  fast.pos = {100, 500};
  fast.vel = {1e160, 0};
  still.id = "still";
  still.pos = {200, 501};
  d.balls = {still, fast};
  auto p = validate(d);
  REQUIRE(p);
  CHECK(p->where == DefProblem::Where::ball);
  CHECK(p->index == 1);
  CHECK(p->field == "vel");
  CHECK(p->message.find("ball 'fast': a speed of 1e+160 units/s is beyond what the engine can time") == 0);
  CHECK(p->message.find("at most 3.5355339") != std::string::npos);  // 1e154 / (2 * 1414.2) units/s
  CHECK(construction_error(d) == p->message);

  // Just under the limit is a scene (the CLI's runaway tests run 1e150 in a 100 x 100 box).
  d.balls[1].vel = {3.5e150, 0};
  CHECK_FALSE(validate(d));

  // A turtle's speed the same way.
  d.balls.pop_back();
  TurtleDef t;
  t.id = "t";
  t.pos = {500, 500};
  t.speed = 1e155;
  d.turtles.push_back(t);
  p = validate(d);
  REQUIRE(p);
  CHECK(p->where == DefProblem::Where::turtle);
  CHECK(p->field == "speed");
}
