// SPDX-License-Identifier: MIT
#include "turtlegas/formats/svg_snapshot.hpp"

#include <sstream>
#include <string>

#include <catch2/catch.hpp>

namespace sim = turtlegas::sim;
namespace tf = turtlegas::formats;

namespace {

std::size_t count(const std::string& s, const std::string& part) {
  std::size_t n = 0;
  for (std::size_t at = s.find(part); at != std::string::npos; at = s.find(part, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("an SVG snapshot draws the arena, walls and balls with +y up") {
  sim::WorldDef def;
  def.name = "a <small> & simple scene";
  def.arena.width = 200;
  def.arena.height = 100;
  def.arena.boundary = sim::Boundary::walls;
  def.walls.push_back({"w", {50, 10}, {50, 90}});
  for (int i = 0; i < 5; ++i) {
    sim::BallDef b;
    b.id = "b" + std::to_string(i);
    b.pos = {20.0 + 30 * i, 50};
    b.vel = {10.0 * i, 0};
    b.radius = 3;
    def.balls.push_back(b);
  }
  const tf::Snapshot snap = tf::snapshot_of(def);
  CHECK(snap.walls.size() == 5);  // the scene's wall and the four arena walls
  CHECK(snap.balls.size() == 5);

  std::ostringstream out;
  tf::write_svg(out, snap, 400.0);
  const std::string svg = out.str();
  CHECK(svg.starts_with("<?xml"));
  CHECK(svg.find("</svg>") != std::string::npos);
  CHECK(count(svg, "<circle") == 5);
  CHECK(count(svg, "<line ") == 5);
  CHECK(svg.find("a &lt;small&gt; &amp; simple scene") != std::string::npos);
  CHECK(svg.find("t = 0 s") != std::string::npos);
  CHECK(svg.find("scale(2 -2)") != std::string::npos);  // 400 px for the 200-unit side, y flipped
  CHECK(svg.find("linearGradient") != std::string::npos);
  // The slowest ball gets the bottom of the palette, the fastest the top.
  CHECK(svg.find("fill=\"#440154\"") != std::string::npos);
  CHECK(svg.find("fill=\"#fde725\"") != std::string::npos);
}

TEST_CASE("an SVG snapshot draws turtles with a heading tick and their id, and pen trails") {
  sim::WorldDef def;
  def.name = "turtles";
  def.arena.width = 100;
  def.arena.height = 100;
  sim::TurtleDef t;
  t.id = "east<1>";
  t.pos = {50, 50};
  t.heading = 1.5707963267948966;  // Logo: 90 degrees, towards +x
  t.radius = 10;
  def.turtles.push_back(t);
  tf::Snapshot snap = tf::snapshot_of(def);
  REQUIRE(snap.turtles.size() == 1);
  snap.turtles[0].trail = {{10, 10}, {10, 50}, {50, 50}};

  std::ostringstream out;
  tf::write_svg(out, snap, 100.0);
  const std::string svg = out.str();
  CHECK(count(svg, "class=\"turtle\"") == 1);
  CHECK(count(svg, "class=\"trail\"") == 1);
  CHECK(svg.find("points=\"10,10 10,50 50,50\"") != std::string::npos);
  // The tick runs from the centre to the rim along the heading: (50, 50) to (60, 50).
  CHECK(svg.find("class=\"heading\" x1=\"50\" y1=\"50\" x2=\"60\" y2=\"50\"") != std::string::npos);
  CHECK(svg.find(">east&lt;1&gt;</text>") != std::string::npos);
  CHECK(svg.find("0 balls, 1 turtle<") != std::string::npos);
  CHECK(svg.find("linearGradient") == std::string::npos);  // no balls, no speed legend
}

TEST_CASE("an SVG snapshot draws moving walls where they are at its time, and absent walls dashed") {
  sim::WorldDef def;
  def.name = "moving";
  def.arena.width = 100;
  def.arena.height = 100;
  sim::WallDef arm{"arm", {10, 10}, {30, 10}};
  arm.keys = {{2.0, {10, 10}, {10, 30}}, {4.0, {50, 10}, {50, 30}}};
  sim::WallDef gate{"gate", {80, 0}, {80, 100}};
  gate.visibility = {{1.0, false}};
  def.walls = {arm, gate};
  // Halfway to the first keyframe the second end is at (20, 20); between the keyframes the wall
  // translates; after the last it stays.
  CHECK(sim::wall_pose(arm, 1.0).to == sim::Vec2{20, 20});
  CHECK(sim::wall_pose(arm, 3.0).from == sim::Vec2{30, 10});
  CHECK(sim::wall_pose(arm, 9.0).to == sim::Vec2{50, 30});
  CHECK(sim::wall_visible(gate, 0.5));
  CHECK_FALSE(sim::wall_visible(gate, 1.0));

  tf::Snapshot snap = tf::snapshot_of(def);
  snap.time = 1.0;
  std::ostringstream out;
  tf::write_svg(out, snap, 100.0);
  const std::string svg = out.str();
  CHECK(svg.find("x1=\"10\" y1=\"10\" x2=\"20\" y2=\"20\"") != std::string::npos);
  CHECK(count(svg, "stroke-dasharray") == 1);
}

TEST_CASE("an SVG snapshot without balls has no legend column; labels stay in the picture (issue 32)") {
  sim::WorldDef def;
  def.name = "edge";
  def.arena.width = 200;
  def.arena.height = 100;
  sim::TurtleDef t;
  t.id = "a-long-turtle-name";
  t.pos = {190, 92};  // at the right edge, near the top
  t.radius = 5;
  def.turtles.push_back(t);
  std::ostringstream out;
  tf::write_svg(out, tf::snapshot_of(def), 400.0);
  const std::string svg = out.str();
  // 400 px of world and two 12 px margins: the 90 px legend column is for balls only.
  CHECK(svg.find("width=\"424\"") != std::string::npos);
  const std::size_t at = svg.find("class=\"turtle-id\" x=\"");
  REQUIRE(at != std::string::npos);
  const double x = std::stod(svg.substr(at + 22));
  const double y = std::stod(svg.substr(svg.find("y=\"", at) + 3));
  // The label's estimated width (0.62 em a character at 11 px) fits left of the right edge, and
  // it is below the top edge.
  CHECK(x + 11 * 0.62 * 18 <= 424);
  CHECK(x < 12 + 185 * 2);  // left of the turtle
  CHECK(y >= 11);

  def.balls.push_back({"b", {20, 20}, {5, 0}, 3});
  std::ostringstream with_balls;
  tf::write_svg(with_balls, tf::snapshot_of(def), 400.0);
  CHECK(with_balls.str().find("width=\"514\"") != std::string::npos);  // the legend column is back
}

TEST_CASE("an SVG snapshot marks walls some turtle passes through (issue 32)") {
  sim::WorldDef def;
  def.arena.width = 100;
  def.arena.height = 100;
  sim::WallDef solid{"solid", {10, 10}, {10, 90}};
  sim::WallDef ghost{"ghost", {50, 10}, {50, 90}};
  ghost.layers.category = 2;  // a category of its own ...
  sim::TurtleDef t;
  t.id = "t";
  t.pos = {30, 50};
  t.layers.mask = ~std::uint32_t{2};  // ... that the turtle does not collide with
  def.walls = {solid, ghost};
  def.turtles.push_back(t);
  REQUIRE(!ghost.layers.collides_with(t.layers));
  REQUIRE(solid.layers.collides_with(t.layers));
  std::ostringstream out;
  tf::write_svg(out, tf::snapshot_of(def), 100.0);
  const std::string svg = out.str();
  CHECK(count(svg, "class=\"wall-passable\"") == 1);
  CHECK(svg.find("class=\"wall-passable\" x1=\"50\"") != std::string::npos);
}
