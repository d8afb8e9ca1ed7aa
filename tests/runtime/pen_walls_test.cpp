// SPDX-License-Identifier: MIT
// Walls laid by a turtle's pen in wall mode: through World::add_wall, at the control step where
// the program resumes; the builder passes through its own walls, everyone else collides with them.
#include <catch2/catch.hpp>

#include <cmath>

#include "fixtures.hpp"
#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/world_server.hpp"

using namespace turtlegas;
using namespace turtlegas::turtle;
using turtlegas::test::arena;
using turtlegas::test::body;

namespace {

TurtleProgram script(const std::string& commands, bool builder = false) {
  TurtleProgram p;
  p.params = nlohmann::json::parse(R"({"commands": )" + commands + "}");
  p.builder = builder;
  return p;
}

const sim::WallDef* find_wall(const sim::World& w, const std::string& id) {
  for (const auto& wall : w.walls())
    if (wall.id == id) return &wall;
  return nullptr;
}

}  // namespace

TEST_CASE("builder layers: a private bit for each builder, masks widened to keep old relations", "[runtime]") {
  sim::WorldDef d = arena();
  d.walls.push_back({"glass", {300, 0}, {300, 400}, {0b10, 0b1}});
  d.turtles.push_back(body("b", {100, 100}, 0));
  d.turtles.push_back(body("ghost", {200, 100}, 0));
  d.turtles.back().layers = {0b100, 0b10};
  d.turtles.push_back(body("c", {250, 100}, 0));
  const sim::WorldDef out = with_builder_layers(d, {script("[]", true), script("[]"), script("[]", true)});
  CHECK(out.turtles[0].layers == sim::Layers{1u << 31, 0xffffffffu});
  CHECK(out.turtles[2].layers == sim::Layers{1u << 30, 0xffffffffu});
  // glass collided with default (the builders' old category): it now collides with both bits.
  CHECK(out.walls[0].layers == sim::Layers{0b10, 0b1 | (1u << 31) | (1u << 30)});
  // the ghost did not collide with default, and still does not collide with the builders.
  CHECK(out.turtles[1].layers == sim::Layers{0b100, 0b10});
}

TEST_CASE("a pen wall stops a second turtle and not its builder; events name it", "[runtime]") {
  sim::WorldDef d = arena();
  // The builder draws x = 100 from y = 50 to y = 250 (4 s at 50/s), then drives back through it.
  d.turtles.push_back(body("builder", {100, 50}, 0));
  d.turtles.push_back(body("t2", {40, 150}, 90, 30));
  std::vector<TurtleProgram> programs = {
      script(R"([["pendown", "wall"], ["forward", 200], ["penup"], ["right", 180], ["forward", 200]])", true),
      script(R"([["wait", 10], ["forward", 100]])")};  // sets off once the builder is home (t = 9)
  WorldServer s(d, programs, base_registry());
  std::vector<LogEvent> log;
  s.set_event_log(&log);
  s.run_until(3.0);
  CHECK(find_wall(s.world(), "builder-w0") == nullptr);  // not before the program resumes
  s.run_until(14.0);
  const sim::WallDef* w = find_wall(s.world(), "builder-w0");
  REQUIRE(w != nullptr);
  CHECK(w->from == sim::Vec2{100, 50});
  CHECK(w->to.x == Approx(100).margin(1e-9));
  CHECK(w->to.y == Approx(250));
  CHECK(w->layers.mask == ~(1u << 31));
  // t2 stops against it: contact at x = 90 after 50 units at 30/s, from t = 10.
  CHECK(s.turtle(1).state.pos.x == Approx(90).margin(1e-9));
  CHECK(s.turtle(1).state.pos.y == Approx(150));
  // The builder drove back through its own wall untouched.
  CHECK(s.turtle(0).state.pos.x == Approx(100).margin(1e-9));
  CHECK(s.turtle(0).state.pos.y == Approx(50).margin(1e-9));
  CHECK(s.turtle(0).fault.empty());
  int drawn = 0;
  bool t2_hit = false;
  for (const auto& e : log) {
    CHECK(e.kind != "wall-refused");
    CHECK(!(e.kind == "turtle-wall" && e.a == "builder"));
    if (e.kind == "wall-drawn") {
      ++drawn;
      CHECK(e.a == "builder");
      CHECK(e.b == "builder-w0");
      CHECK(e.t == Approx(4.0));
    }
    if (e.kind == "turtle-wall" && e.a == "t2" && e.b == "builder-w0") {
      t2_hit = true;
      CHECK(e.t == Approx(10 + 50.0 / 30));
    }
  }
  CHECK(drawn == 1);
  CHECK(t2_hit);
}

TEST_CASE("a touch-cut stroke lays the part it drove; pen_mode and the builder rule", "[runtime]") {
  sim::WorldDef d = arena();
  d.walls.push_back({"stop", {100, 200}, {300, 200}});
  d.turtles.push_back(body("b", {200, 50}, 0));
  d.turtles.push_back(body("nb", {50, 50}, 0));
  Registry r = base_registry();
  static PenMode seen_mode;
  static std::string refused;
  r.add("build", [](Turtle& t, const Params&) {
    t.pen_down(PenMode::wall);
    seen_mode = t.pen_mode();
    t.forward(500);  // cut short at y = 190
    t.pen_up();
    t.back(20);
  });
  r.add("not_builder", [](Turtle& t, const Params&) { t.pen_down(PenMode::wall); });
  TurtleProgram build, nb;
  build.controller = "build";
  build.builder = true;
  nb.controller = "not_builder";
  WorldServer s(d, {build, nb}, r);
  s.run_until(10.0);
  CHECK(seen_mode == PenMode::wall);
  const sim::WallDef* w = find_wall(s.world(), "b-w0");
  REQUIRE(w != nullptr);
  CHECK(w->to.y == Approx(190));
  CHECK(find_wall(s.world(), "b-w1") == nullptr);  // pen up for the back stroke
  CHECK(s.turtle(0).state.pos.y == Approx(170));
  CHECK(s.turtle(1).fault.find("may not lay walls") != std::string::npos);
}

TEST_CASE("a pen wall that would overlap another body is refused, not laid", "[runtime]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("b", {100, 50}, 0));
  // "late" drives into the stroke's band after the builder has passed (t = 3.475), before the
  // stroke ends and its wall is laid (t = 4), and stays there.
  d.turtles.push_back(body("late", {300, 150}, 270, 200));
  std::vector<TurtleProgram> programs = {script(R"([["pendown", "wall"], ["forward", 200]])", true),
                                         script(R"([["wait", 2.5], ["forward", 195]])")};
  WorldServer s(d, programs, base_registry());
  std::vector<LogEvent> log;
  s.set_event_log(&log);
  s.run_until(6.0);
  bool refused = false;
  for (const auto& e : log)
    if (e.kind == "wall-refused") {
      refused = true;
      CHECK(e.a == "b");
      CHECK(e.b == "b-w0");
      CHECK(!e.message.empty());
    }
  CHECK(refused);
  CHECK(find_wall(s.world(), "b-w0") == nullptr);
  CHECK(s.turtle(0).fault.empty());
}
