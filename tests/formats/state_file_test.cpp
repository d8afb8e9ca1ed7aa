// SPDX-License-Identifier: MIT
// The state file (formats/state_file.hpp): its shape, and headings in the degrees a program sees.
#include <catch2/catch.hpp>

#include <cstring>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "turtlegas/formats/names.hpp"
#include "turtlegas/formats/state_file.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/world_server.hpp"

using namespace turtlegas;

namespace {

sim::WorldDef scene(double heading_degrees) {
  sim::WorldDef d;
  d.arena.width = d.arena.height = 400;
  d.arena.boundary = sim::Boundary::walls;
  d.dt = 0.1;
  sim::BallDef b;
  b.id = "b\"1";  // an id that needs escaping
  b.pos = {300, 300};
  b.vel = {-1.5, 0.25};
  b.radius = 5;
  d.balls.push_back(b);
  sim::TurtleDef t;
  t.id = "t1";
  t.pos = {100, 100};
  t.heading = sim::to_radians(heading_degrees);
  t.radius = 10;
  d.turtles.push_back(t);
  return d;
}

}  // namespace

TEST_CASE("the state file holds live balls and turtles, headings in [0, 360) as the program reads them", "[formats]") {
  // 0.375 degrees: to_radians and back by h * (180/pi) gives 0.37500000000000006, by h / (pi/180)
  // 0.375. A program and the state file must say the same heading, bit for bit.
  for (double heading : {0.375, 90.0, 271.5, 359.9}) {
    CAPTURE(heading);
    const sim::WorldDef def = scene(heading);
    double seen = -1.0;
    turtle::Registry registry;
    registry.add("look", [&](turtle::Turtle& t, const turtle::Params&) {
      seen = t.heading();
      t.wait(1.0);
    });
    turtle::TurtleProgram program;
    program.controller = "look";
    turtle::WorldServer server(def, {program}, registry);
    server.run_until(0.5);
    const formats::IdTable ids = formats::ball_ids(def);
    std::ostringstream out;
    formats::write_state(out, server.world(), formats::RunNames{ids, def, server.world()});
    const nlohmann::json j = nlohmann::json::parse(out.str());
    CHECK(j.at("t") == 0.5);
    REQUIRE(j.at("balls").size() == 1);
    CHECK(j["balls"][0].at("id") == "b\"1");
    CHECK(j["balls"][0].at("vel") == nlohmann::json::array({-1.5, 0.25}));
    REQUIRE(j.at("turtles").size() == 1);
    CHECK(j["turtles"][0].at("id") == "t1");
    CHECK(j["turtles"][0].at("pos") == nlohmann::json::array({100.0, 100.0}));
    const double written = j["turtles"][0].at("heading").get<double>();
    CHECK(std::memcmp(&written, &seen, sizeof(double)) == 0);
    CHECK(written >= 0.0);
    CHECK(written < 360.0);
  }
  // Exactly: 0.375 is what the world file said.
  const sim::WorldDef def = scene(0.375);
  const sim::World world(def, sim::Mode::exact);
  const formats::IdTable ids = formats::ball_ids(def);
  std::ostringstream out;
  formats::write_state(out, world, formats::RunNames{ids, def, world});
  CHECK(nlohmann::json::parse(out.str())["turtles"][0].at("heading") == 0.375);
}

TEST_CASE("a crushed turtle is not in the state file, as an exited ball is not", "[formats][regression]") {
  // Issue 28 item 4: the state file listed a crushed turtle where it was, with the piston that
  // crushed it then passing through it.
  sim::WorldDef d;
  d.arena.width = 300;
  d.arena.height = 200;
  d.arena.boundary = sim::Boundary::walls;
  sim::WallDef w;
  w.id = "piston";
  w.from = {20, 10};
  w.to = {20, 190};
  w.keys.push_back({10.0, {290, 10}, {290, 190}});
  d.walls.push_back(w);
  sim::TurtleDef t;
  t.id = "crushed";
  t.pos = {150, 150};
  t.radius = 8;
  d.turtles.push_back(t);
  t.id = "kept";  // above the piston's top end (y = 190): it passes by
  t.pos = {150, 196};
  t.radius = 3;
  d.turtles.push_back(t);
  for (sim::Mode mode : {sim::Mode::exact, sim::Mode::step}) {
    sim::World world(d, mode);
    world.advance_to(12.0);
    CHECK_FALSE(world.turtle_alive(0));
    CHECK(world.turtle_alive(1));
    const formats::IdTable ids = formats::ball_ids(d);
    std::ostringstream out;
    formats::write_state(out, world, formats::RunNames{ids, d, world});
    const nlohmann::json j = nlohmann::json::parse(out.str());
    REQUIRE(j.at("turtles").size() == 1);
    CHECK(j["turtles"][0].at("id") == "kept");
  }
}
