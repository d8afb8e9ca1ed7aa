// SPDX-License-Identifier: MIT
// World files: collision layers by named category, `draw` builders, and the expectations that go
// with them (it, walls, wall).
#include <catch2/catch.hpp>

#include "file_errors.hpp"

#include <string>

#include "turtlegas/world/draw_walker.hpp"
#include "turtlegas/world/scenario.hpp"
#include "turtlegas/world/world_file.hpp"

namespace tw = turtlegas::world;
namespace tt = turtlegas::turtle;
namespace sim = turtlegas::sim;

using turtlegas::test::contains;

namespace {

std::string world(const std::string& body) { return R"({"format": "turtlegas-world/1")" + body + "}"; }

tw::Scene scene(const std::string& text) { return tw::parse_scene(text, "w.json", tt::base_registry()); }

tw::WorldFileError error_of(const std::string& text) { return turtlegas::test::error_of(scene, text); }

}  // namespace

TEST_CASE("categories get bits in section order; collides_with makes the mask") {
  const tw::Scene s = scene(world(R"(,
    "walls": [{"id": "w", "from": [0, 0], "to": [10, 0], "category": "walls"},
              {"id": "glass", "from": [0, 50], "to": [10, 50], "category": "walls", "collides_with": ["default", "ghost"]},
              {"id": "plain", "from": [0, 90], "to": [10, 90]}],
    "balls": [{"id": "b", "pos": [50, 50], "radius": 1, "category": ["gas", "walls"], "collides_with": "walls"}],
    "gas": [{"count": 3, "radius": 1, "speed": 1, "region": [[100, 100], [200, 200]], "category": "gas",
             "collides_with": []}],
    "turtles": [{"id": "g", "pos": [300, 300], "category": "ghost", "collides_with": ["walls"]}])"));
  // default = bit 0, then walls, gas (first seen in balls), ghost.
  const auto& w = s.def.walls;
  CHECK(w[0].layers == sim::Layers{0b10, 0xffffffffu});
  CHECK(w[1].layers == sim::Layers{0b10, 0b1001});
  CHECK(w[2].layers == sim::Layers{});
  CHECK(s.def.balls[0].layers == sim::Layers{0b110, 0b10});
  for (std::size_t i = 1; i < s.def.balls.size(); ++i) CHECK(s.def.balls[i].layers == sim::Layers{0b100, 0});
  CHECK(s.def.turtles[0].layers == sim::Layers{0b1000, 0b10});
  // The collision rule, as the docs state it.
  CHECK(s.def.turtles[0].layers.collides_with(w[0].layers));
  CHECK(s.def.turtles[0].layers.collides_with(w[1].layers));
  CHECK(!s.def.turtles[0].layers.collides_with(s.def.balls[0].layers));
}

TEST_CASE("layer keys: errors name their JSON path") {
  CHECK_ERROR(world(R"(, "walls": [{"id": "w", "from": [0, 0], "to": [10, 0], "collides_with": ["wals"]}])"),
              "/walls/0/collides_with/0", "unknown category \"wals\"");
  CHECK_ERROR(world(R"(, "turtles": [{"id": "t", "pos": [50, 50], "collides_with": "ghost"}])"),
              "/turtles/0/collides_with", "unknown category \"ghost\"");
  CHECK_ERROR(world(R"(, "balls": [{"id": "b", "pos": [5, 5], "radius": 1, "category": 3}])"), "/balls/0/category",
              "category must be a name");
  CHECK_ERROR(world(R"(, "balls": [{"id": "b", "pos": [5, 5], "radius": 1, "category": []}])"), "/balls/0/category",
              "non-empty list");
  CHECK_ERROR(world(R"(, "balls": [{"id": "b", "pos": [5, 5], "radius": 1, "category": [""]}])"),
              "/balls/0/category/0", "must not be empty");
  CHECK_ERROR(world(R"(, "gas": [{"count": 1, "radius": 1, "speed": 1, "collides_with": ["x"]}])"),
              "/gas/0/collides_with/0", "unknown category \"x\"");
  // "default" is always known.
  CHECK_NOTHROW(scene(world(R"(, "turtles": [{"id": "t", "pos": [50, 50], "collides_with": ["default"]}])")));
  // 31 names besides default fit; a 32nd does not.
  std::string walls;
  for (int k = 0; k < 32; ++k)
    walls += (k ? "," : "") + std::string(R"({"id": "w)") + std::to_string(k) + R"(", "from": [0, )" +
             std::to_string(k + 1) + R"(], "to": [10, )" + std::to_string(k + 1) + R"(], "category": "c)" +
             std::to_string(k) + "\"}";
  CHECK_ERROR(world(R"(, "walls": [)" + walls + "]"), "/walls/31/category", "too many collision categories");
}

TEST_CASE("bodies that do not collide may overlap") {
  // A turtle standing on a wall it does not collide with is a sound world.
  CHECK_NOTHROW(scene(world(R"(, "walls": [{"id": "w", "from": [0, 50], "to": [100, 50], "category": "walls",
      "collides_with": "default"}], "turtles": [{"id": "t", "pos": [50, 50], "category": "ghost"}])")));
  CHECK_ERROR(world(R"(, "walls": [{"id": "w", "from": [0, 50], "to": [100, 50]}],
                      "turtles": [{"id": "t", "pos": [50, 50]}])"),
              "/turtles/0/pos", "overlaps wall");
}

TEST_CASE("the draw walker lays exact walls") {
  tw::DrawWalker b("b", {100, 100}, 90);
  CHECK(!b.move(10));  // pen up: no wall
  b.pen_down = true;
  auto w = b.move(100);
  REQUIRE(w);
  CHECK(w->id == "b-w0");
  CHECK(w->from == sim::Vec2{110, 100});
  CHECK(w->to == sim::Vec2{210, 100});
  b.turn(90);  // heading 180: -y
  w = b.move(50);
  REQUIRE(w);
  CHECK(w->id == "b-w1");
  CHECK(w->to == sim::Vec2{210, 50});
  b.turn(-270);  // left 270 = right 90: heading 270, -x
  w = b.move(-20);  // back 20: +x
  REQUIRE(w);
  CHECK(w->to == sim::Vec2{230, 50});
  CHECK(!b.move(0));
  CHECK(b.walls() == 3);
  CHECK(tw::heading_direction(-90) == sim::Vec2{-1, 0});
  CHECK(tw::heading_direction(720) == sim::Vec2{0, 1});
}

TEST_CASE("draw builders: walls appended after the file's, with their layers and paths") {
  const tw::Scene s = scene(world(R"(,
    "walls": [{"id": "w", "from": [0, 0], "to": [10, 0], "category": "walls"}],
    "draw": [{"id": "builder", "pos": [100, 100], "heading": 90, "category": "walls", "collides_with": ["default"],
              "commands": [["pendown"], ["forward", 100], ["right", 90], ["forward", 50], ["penup"], ["forward", 10],
                           ["pendown"], ["left", 90], ["back", 30]]}])"));
  REQUIRE(s.def.walls.size() == 4);
  const auto& w = s.def.walls;
  CHECK(w[1].id == "builder-w0");
  CHECK(w[1].from == sim::Vec2{100, 100});
  CHECK(w[1].to == sim::Vec2{200, 100});
  CHECK(w[2].id == "builder-w1");
  CHECK(w[2].from == sim::Vec2{200, 100});
  CHECK(w[2].to == sim::Vec2{200, 50});
  CHECK(w[3].id == "builder-w2");
  CHECK(w[3].from == sim::Vec2{200, 40});
  CHECK(w[3].to == sim::Vec2{170, 40});
  CHECK(w[3].layers == sim::Layers{0b10, 0b1});

  CHECK_ERROR(world(R"(, "draw": [{"id": "b", "pos": [0, 0], "commands": [["pendown"], ["wait", 1]]}])"),
              "/draw/0/commands/1/0", "unknown command 'wait'");
  CHECK_ERROR(world(R"(, "draw": [{"id": "b", "pos": [0, 0], "commands": [["forward"]]}])"), "/draw/0/commands/0",
              "needs one number");
  CHECK_ERROR(world(R"(, "draw": [{"id": "b", "pos": [0, 0], "commands": []}, {"id": "b", "pos": [0, 0], "commands": []}])"),
              "/draw/1/id", "duplicate id");
  CHECK_ERROR(world(R"(, "walls": [{"id": "b-w0", "from": [0, 0], "to": [1, 1]}],
                      "draw": [{"id": "b", "pos": [5, 5], "commands": [["pendown"], ["forward", 10]]}])"),
              "/draw/0/commands/1", "already used at /walls/0/id");
  CHECK_ERROR(world(R"(, "draw": [{"id": "b", "pos": [5, 5], "comands": []}])"), "/draw/0/comands", "did you mean");
  // Validated like other walls: a drawn wall through a ball is reported at the command that laid it.
  CHECK_ERROR(world(R"(, "balls": [{"id": "x", "pos": [50, 50], "radius": 2}],
                      "draw": [{"id": "b", "pos": [0, 50], "heading": 90, "commands": [["pendown"], ["forward", 100]]}])"),
              "/balls/0/pos", "overlaps wall 'b-w0'");
}

TEST_CASE("pen walls in the file: pen \"wall\", builder, script pen modes") {
  tw::Scene s = scene(world(R"(, "turtles": [
      {"id": "a", "pos": [50, 50], "pen": "wall"},
      {"id": "b", "pos": [100, 50], "params": {"commands": [["pendown", "wall"], ["forward", 1]]}},
      {"id": "c", "pos": [150, 50], "builder": true},
      {"id": "d", "pos": [200, 50], "params": {"commands": [["pendown", "line"]]}}])"));
  CHECK(s.programs[0].pen_walls);
  CHECK(s.programs[0].builder);
  CHECK(!s.programs[1].pen_walls);
  CHECK(s.programs[1].builder);
  CHECK(s.programs[2].builder);
  CHECK(!s.programs[3].builder);
  CHECK_ERROR(world(R"(, "turtles": [{"id": "a", "pos": [50, 50], "pen": "wall", "builder": false}])"),
              "/turtles/0/builder", "lays walls");
  CHECK_ERROR(world(R"(, "turtles": [{"id": "a", "pos": [50, 50], "params": {"commands": [["pendown", "brick"]]}}])"),
              "/turtles/0/params/commands/0/1", "a pen mode is");
}

TEST_CASE("expectations: it, walls, wall") {
  const std::string turtles = R"(, "turtles": [{"id": "t1", "pos": [50, 50]}, {"id": "t2", "pos": [100, 50]}])";
  CHECK_ERROR(world(turtles + R"(, "expect": [{"it": "t2"}])"), "/expect/0/it", "needs a game");
  CHECK_ERROR(world(turtles + R"(, "game": {"kind": "tag"}, "expect": [{"it": "t3"}])"), "/expect/0/it",
              "no turtle has id");
  CHECK_ERROR(world(turtles + R"(, "expect": [{"walls": 1.5}])"), "/expect/0/walls", "whole number");
  CHECK_ERROR(world(turtles + R"(, "expect": [{"walls": "*"}])"), "/expect/0", "needs \"min\"");
  CHECK_ERROR(world(turtles + R"(, "expect": [{"walls": 1, "drawn_by": "t9"}])"), "/expect/0/drawn_by", "no turtle");
  CHECK_ERROR(world(turtles + R"(, "expect": [{"wall": "x", "exists": 1}])"), "/expect/0/exists", "true or false");
  // A wall a turtle may draw can be named before it exists.
  CHECK_NOTHROW(scene(world(turtles + R"(, "expect": [{"event": "wall-drawn", "b": "t1-w3"}])")));
  CHECK_ERROR(world(turtles + R"(, "expect": [{"event": "wall-drawn", "b": "t1-wx"}])"), "/expect/0/b", "no wall");

  tw::Scene s = scene(world(R"(, "game": {"kind": "tag", "it": "t1"},
      "turtles": [{"id": "t1", "pos": [50, 100], "heading": 90, "params": {"commands": [["forward", 100]]}},
                  {"id": "t2", "pos": [100, 100]}],
      "expect": [{"until": 2}, {"it": "t1", "at": 0.5}, {"it": "t2"}, {"walls": 0}, {"wall": "zz", "exists": false}])"));
  auto r = tw::run_expectations(s, tt::base_registry(), sim::Mode::exact);
  CHECK(r.failures.empty());
  s = scene(world(R"(, "game": {"kind": "tag", "it": "t1"},
      "turtles": [{"id": "t1", "pos": [50, 100]}, {"id": "t2", "pos": [100, 100]}],
      "expect": [{"until": 1}, {"it": "t2"}, {"walls": 2}, {"wall": "zz"}])"));
  r = tw::run_expectations(s, tt::base_registry(), sim::Mode::exact);
  REQUIRE(r.failures.size() == 3);
  CHECK(contains(r.failures[0], "expect[1] it t2: \"it\" is t1 at t = 1"));
  CHECK(contains(r.failures[1], "walls = 0 at t = 1, wanted = 2"));
  CHECK(contains(r.failures[2], "wall zz: no such wall"));
}
