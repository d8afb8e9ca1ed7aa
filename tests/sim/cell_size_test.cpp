// SPDX-License-Identifier: MIT
// The cell-size policy (sim/src/engine/cell_size.cpp) on its own: each branch of the rule, with the
// numbers it must give.
#include <cmath>
#include <stdexcept>
#include <string>

#include <catch2/catch.hpp>

#include "engine/cell_size.hpp"
#include "turtlegas/sim/world_def.hpp"

using namespace turtlegas::sim;
using turtlegas::sim::detail::choose_cell_size;

namespace {

WorldDef arena(double width, double height, Boundary boundary = Boundary::none) {
  WorldDef d;
  d.arena.width = width;
  d.arena.height = height;
  d.arena.boundary = boundary;
  return d;
}

BallDef ball(double radius, Vec2 vel = {}) {
  BallDef b;
  b.pos = {1.0, 1.0};
  b.vel = vel;
  b.radius = radius;
  return b;
}

std::string message_of(const WorldDef& d, Mode mode) {
  try {
    choose_cell_size(d, mode);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("an explicit cell is taken as it is when it obeys the rule", "[cell_size]") {
  WorldDef d = arena(100, 100);
  d.balls.push_back(ball(5.0, {30.0, 40.0}));  // speed 50
  d.dt = 0.1;
  d.arena.cell = 10.0;  // exactly the diameter: exact mode accepts it
  CHECK(choose_cell_size(d, Mode::exact) == 10.0);
  d.arena.cell = 20.0;  // 2 (5 + 50 x 0.1): step mode's rule, exactly
  CHECK(choose_cell_size(d, Mode::step) == 20.0);
}

TEST_CASE("an explicit cell too small is an error that gives the number and the remedies", "[cell_size]") {
  WorldDef d = arena(100, 100);
  d.balls.push_back(ball(5.0, {30.0, 40.0}));
  d.dt = 0.1;
  d.arena.cell = 8.0;
  CHECK(message_of(d, Mode::exact) ==
        "arena.cell 8.000000 is too small: exact mode needs cells at least as wide as the largest ball or turtle "
        "(diameter 10.000000); set arena.cell >= that");
  d.arena.cell = 19.0;
  CHECK(message_of(d, Mode::step) ==
        "arena.cell 19.000000 is too small: the memo's rule in step mode needs cells wider than twice (largest radius + "
        "largest speed x dt) = 20.000000; set arena.cell >= that, use a smaller dt, or use --mode exact");
  // Turtles count with their radius and their speed.
  WorldDef t = arena(100, 100);
  TurtleDef turtle;
  turtle.radius = 3.0;
  turtle.speed = 10.0;
  t.turtles.push_back(turtle);
  t.dt = 0.5;
  t.arena.cell = 5.0;
  CHECK_THAT(message_of(t, Mode::exact), Catch::Contains("(diameter 6.000000)"));
  t.arena.cell = 15.0;
  CHECK_THAT(message_of(t, Mode::step), Catch::Contains("= 16.000000;"));
}

TEST_CASE("exact mode with balls that meet walls only sizes cells by the walls", "[cell_size]") {
  // 200 x 100 with its four walls (length 600) and balls that pass through each other: about one
  // wall per cell, area / length.
  WorldDef d = arena(200, 100, Boundary::walls);
  d.effects.ball_ball = false;
  for (int k = 0; k < 50; ++k) d.balls.push_back(ball(1.0));
  CHECK(choose_cell_size(d, Mode::exact) == 200.0 * 100.0 / 600.0);
  // A moving wall is not in the table and does not count.
  WallDef moving;
  moving.from = {10, 10};
  moving.to = {110, 10};
  moving.keys.push_back({1.0, {10, 20}, {110, 20}});
  d.walls.push_back(moving);
  CHECK(choose_cell_size(d, Mode::exact) == 200.0 * 100.0 / 600.0);
  // A fixed one does: 20000 / 700.
  WallDef fixed;
  fixed.from = {10, 50};
  fixed.to = {110, 50};
  d.walls.push_back(fixed);
  CHECK(choose_cell_size(d, Mode::exact) == 200.0 * 100.0 / 700.0);
  // No walls at all (exits only): a quarter of the arena's longer side, also the most it gives.
  WorldDef open = arena(200, 100);
  open.effects.ball_ball = false;
  open.balls.push_back(ball(1.0));
  CHECK(choose_cell_size(open, Mode::exact) == 50.0);
  WallDef short_wall;
  short_wall.from = {0, 0};
  short_wall.to = {10, 0};
  open.walls.push_back(short_wall);  // 20000 / 10 = 2000, capped at the quarter
  CHECK(choose_cell_size(open, Mode::exact) == 50.0);
  // Step mode, or a turtle in the scene, takes the 0.3 bodies per cell rule instead.
  CHECK(choose_cell_size(d, Mode::step) == std::sqrt(0.3 * 200.0 * 100.0 / 50.0));
  TurtleDef turtle;
  turtle.radius = 1.0;
  d.turtles.push_back(turtle);
  CHECK(choose_cell_size(d, Mode::exact) == std::sqrt(0.3 * 200.0 * 100.0 / 51.0));
}

TEST_CASE("otherwise cells hold about 0.3 bodies, and are never narrower than the rule", "[cell_size]") {
  WorldDef d = arena(100, 100);
  for (int k = 0; k < 30; ++k) d.balls.push_back(ball(0.1));
  CHECK(choose_cell_size(d, Mode::exact) == 10.0);  // sqrt(0.3 x 10^4 / 30)
  CHECK(choose_cell_size(d, Mode::step) == 10.0);
  // Large balls: the rule, widened by a relative 1e-9 so that touching bodies stay in neighbours.
  for (auto& b : d.balls) b.radius = 8.0;
  CHECK(choose_cell_size(d, Mode::exact) == 16.0 * (1.0 + 1e-9));
  // Step mode's rule adds the paths of one step.
  d.balls[0].vel = {0.0, 60.0};
  d.dt = 0.1;
  CHECK(choose_cell_size(d, Mode::step) == 2.0 * (8.0 + 6.0) * (1.0 + 1e-9));
  CHECK(choose_cell_size(d, Mode::exact) == 16.0 * (1.0 + 1e-9));
  // An empty scene: a sixteenth of the longer side.
  CHECK(choose_cell_size(arena(320, 100), Mode::exact) == 20.0);
}

TEST_CASE("the table stays under about 4e7 cells", "[cell_size]") {
  // Walls only, with 10^7 units of wall in a 1000 x 1000 arena: one wall per cell would mean cells
  // of 0.1, 10^8 of them; the cap gives sqrt(area / 4e7) instead.
  WorldDef d = arena(1000, 1000);
  d.effects.ball_ball = false;
  d.balls.push_back(ball(0.01));
  WallDef w;
  w.from = {0, 0};
  w.to = {1e7, 0};
  d.walls.push_back(w);
  const double cap = std::sqrt(1e6 / 4.0e7);
  CHECK(choose_cell_size(d, Mode::exact) == cap);
  CHECK(1e6 / (cap * cap) <= 4.0e7 * (1 + 1e-12));
}

TEST_CASE("a periodic arena gets three cells across unless the rule forbids it", "[cell_size]") {
  WorldDef d = arena(30, 60, Boundary::periodic);
  d.balls.push_back(ball(1.0));  // 0.3 per cell would be sqrt(540) = 23.2 wide
  CHECK(choose_cell_size(d, Mode::exact) == 10.0);
  CHECK(choose_cell_size(d, Mode::step) == 10.0);
  d.balls[0].radius = 6.0;  // a diameter of 12: three cells of 10 would split touching discs
  CHECK(choose_cell_size(d, Mode::exact) == 12.0 * (1.0 + 1e-9));
  // (the engine then refuses the scene: fewer than 3 cells across; world_test.cpp)
}
