// SPDX-License-Identifier: MIT
// The world file's `turtles`: defaults, degrees to radians at the boundary, programs, and a clear
// error with its JSON path for each kind of bad input.
#include <cmath>
#include <numbers>
#include <string>

#include <catch2/catch.hpp>

#include "file_errors.hpp"

#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/world/world_file.hpp"

namespace tw = turtlegas::world;
namespace tt = turtlegas::turtle;
namespace sim = turtlegas::sim;

using turtlegas::test::contains;

namespace {

constexpr double deg = std::numbers::pi / 180.0;

const tt::Registry& registry() {
  static const tt::Registry r = turtlegas::controllers::builtin_registry();
  return r;
}

/// A world file with a 400 x 300 walled arena and the given `turtles` array (its text).
std::string world(const std::string& turtles, const std::string& extra = "") {
  return R"({"format": "turtlegas-world/1", "arena": {"width": 400, "height": 300, "boundary": "walls"})" + extra +
         R"(, "turtles": )" + turtles + "}";
}

/// One turtle at (100, 100) with the given extra keys (text starting with a comma, or empty).
std::string one(const std::string& keys) { return world(R"([{"id": "t", "pos": [100, 100])" + keys + "}]"); }

tw::Scene parse(const std::string& text) { return tw::parse_scene(text, "w.json", registry()); }

tw::WorldFileError error_of(const std::string& text) { return turtlegas::test::error_of(parse, text); }

}  // namespace

TEST_CASE("a turtle gets the documented defaults") {
  const tw::Scene s = parse(one(""));
  REQUIRE(s.def.turtles.size() == 1);
  REQUIRE(s.programs.size() == 1);
  const sim::TurtleDef& t = s.def.turtles[0];
  CHECK(t.id == "t");
  CHECK(t.pos == sim::Vec2{100, 100});
  CHECK(t.heading == 0.0);
  CHECK(t.radius == 10.0);
  CHECK(t.speed == 30.0);
  CHECK(t.turn_rate == Approx(90 * deg).epsilon(1e-15));
  CHECK(t.bounce < 0.0);  // dead stop
  const tt::TurtleProgram& p = s.programs[0];
  CHECK(p.controller == "script");
  CHECK(p.params == nlohmann::json::object());
  REQUIRE(p.sensors.size() == 4);
  CHECK(p.sensors[0].name == "front");
  CHECK(p.sensors[0].from == -45);
  CHECK(p.sensors[0].to == 45);
  CHECK(p.sensors[3].name == "left");
  CHECK_FALSE(p.pen_down);
  CHECK_FALSE(p.gps);
}

TEST_CASE("a full turtle entry parses, with degrees converted to radians") {
  const tw::Scene s = parse(world(R"([
    {"id": "a", "pos": [50, 60], "heading": 90, "radius": 7, "speed": 45, "turn_rate": 180,
     "controller": "wander", "params": {"back_off": 8, "x-note": "kept"}, "sensors": 6, "pen": "down",
     "gps": true, "bounce": 0.5, "x-colour": "red"},
    {"id": "b", "pos": [300, 200], "heading": -90, "controller": "spiral", "pen": true,
     "sensors": [{"name": "nose", "from": -10, "to": 10}, {"name": "tail", "from": 170, "to": 190}]},
    {"id": "c", "pos": [300, 60], "heading": 450, "pen": "up", "gps": false, "bounce": 0}])"));
  REQUIRE(s.def.turtles.size() == 3);
  const sim::TurtleDef &a = s.def.turtles[0], &b = s.def.turtles[1], &c = s.def.turtles[2];
  CHECK(a.heading == Approx(std::numbers::pi / 2).epsilon(1e-15));
  CHECK(a.radius == 7);
  CHECK(a.speed == 45);
  CHECK(a.turn_rate == Approx(std::numbers::pi).epsilon(1e-15));
  CHECK(a.bounce == 0.5);
  CHECK(b.heading == Approx(1.5 * std::numbers::pi).epsilon(1e-15));  // -90 is 270
  CHECK(c.heading == Approx(std::numbers::pi / 2).epsilon(1e-15));    // 450 is 90
  CHECK(c.bounce == 0.0);

  const tt::TurtleProgram &pa = s.programs[0], &pb = s.programs[1], &pc = s.programs[2];
  CHECK(pa.controller == "wander");
  CHECK(pa.params.at("back_off") == 8);
  CHECK(pa.params.contains("x-note"));  // params belong to the controller, passed on whole
  REQUIRE(pa.sensors.size() == 6);
  CHECK(pa.sensors[0].name == "s0");
  CHECK(pa.sensors[0].from == -30);
  CHECK(pa.sensors[0].to == 30);
  CHECK(pa.pen_down);
  CHECK(pa.gps);
  CHECK(pb.controller == "spiral");
  CHECK(pb.pen_down);
  REQUIRE(pb.sensors.size() == 2);
  CHECK(pb.sensors[1].name == "tail");
  CHECK(pb.sensors[1].from == 170);
  CHECK(pb.sensors[1].to == 190);
  CHECK(pc.controller == "script");
  CHECK_FALSE(pc.pen_down);
  CHECK_FALSE(pc.gps);
}

TEST_CASE("a script turtle's commands are checked at load time") {
  const tw::Scene s = parse(one(R"(, "params": {"commands": [["forward", 100], ["right", 90], ["pendown"],
                                  ["back", 5], ["left", 30], ["wait", 0.5], ["penup"]]})"));
  CHECK(s.programs[0].params.at("commands").size() == 7);
  const std::string c = "/turtles/0/params/commands";
  CHECK_ERROR(one(R"(, "params": {"commands": [["forward", 10], ["fowrard", 10]]})"), c + "/1/0",
              "unknown command 'fowrard'; known: forward, back, left, right, wait, pendown, penup, sense, camera, arc, drive, wheels");
  CHECK_ERROR(one(R"(, "params": {"commands": [["forward"]]})"), c + "/0", "'forward' needs one number");
  CHECK_ERROR(one(R"(, "params": {"commands": [["forward", 1, 2]]})"), c + "/0", "'forward' needs one number");
  CHECK_ERROR(one(R"(, "params": {"commands": [["right", "ninety"]]})"), c + "/0/1", "expected a number, got a string");
  CHECK_ERROR(one(R"(, "params": {"commands": [["pendown", 1]]})"), c + "/0", "'pendown' takes no amount");
  CHECK_ERROR(one(R"(, "params": {"commands": [["wait", -1]]})"), c + "/0/1", "'wait' needs an amount >= 0 in seconds");
  // Negative distances and angles are directions, as in the Turtle API (docs/controllers.md).
  CHECK(parse(one(R"(, "params": {"commands": [["forward", -1], ["back", -2], ["left", -30], ["right", -45]]})"))
            .programs[0]
            .params.at("commands")
            .size() == 4);
  CHECK_ERROR(one(R"(, "params": {"commands": ["forward", 10]})"), c + "/0", "a command must be [command, amount]");
  CHECK_ERROR(one(R"(, "params": {"commands": {"forward": 10}})"), c, "commands must be a list of [command, amount]");
  CHECK_ERROR(one(R"(, "params": {"comands": []})"), "/turtles/0/params/comands",
              "unknown key \"comands\" in the script controller's params; did you mean \"commands\"?");
}

TEST_CASE("a script's arcs and a turtle's axle are checked at load time", "[arc]") {
  const tw::Scene s = parse(one(R"(, "axle": 25, "params": {"commands": [["arc", 50, -90], ["drive", -20, 45, 2],
                                  ["wheels", 10, 30, 1.5]]})"));
  CHECK(s.programs[0].params.at("commands").size() == 3);
  CHECK(s.programs[0].axle == 25.0);
  CHECK(parse(one("")).programs[0].axle == 0.0);  // the runtime's default: twice the radius
  const std::string c = "/turtles/0/params/commands";
  CHECK_ERROR(one(R"(, "params": {"commands": [["arc", 50]]})"), c + "/0",
              "'arc' needs 2 numbers (units (radius) and degrees), e.g. [\"arc\", 50, 90]");
  CHECK_ERROR(one(R"(, "params": {"commands": [["drive", 1, 2]]})"), c + "/0", "'drive' needs 3 numbers");
  CHECK_ERROR(one(R"(, "params": {"commands": [["wheels", 1, "2", 3]]})"), c + "/0/2", "expected a number, got a string");
  CHECK_ERROR(one(R"(, "params": {"commands": [["arc", -5, 90]]})"), c + "/0/1", "an arc's radius must be >= 0");
  CHECK_ERROR(one(R"(, "params": {"commands": [["wheels", 1, 2, -3]]})"), c + "/0/3", "'wheels' needs a time >= 0");
  CHECK_ERROR(one(R"(, "axle": 0)"), "/turtles/0/axle",
              "axle (units between the wheels) must be > 0 (got 0); leave it out for twice the turtle's radius");
  CHECK_ERROR(one(R"(, "axle": "wide")"), "/turtles/0/axle", "expected a number");
}

TEST_CASE("an unregistered controller names the registered ones") {
  const std::string text = world(R"([{"id": "a", "pos": [50, 50]}, {"id": "b", "pos": [100, 50]},
                                     {"id": "c", "pos": [150, 50], "controller": "wandr"}])");
  const tw::WorldFileError e = error_of(text);
  CHECK(std::string(e.what()) ==
        "w.json: /turtles/2/controller: controller 'wandr' is not registered; known: braitenberg, epuck_swarm, mirror, script, spiral, square, "
        "tag_camera, tag_chaser, tag_evader, tag_random, tag_seeing, wall_follower, wander; did you mean 'wander'?");
  // Without a registry (load_world_file, parse_world: the bodies only) names are not checked.
  CHECK(tw::parse_world(text, "w.json").turtles.size() == 3);
  // A registry of one's own decides what is known.
  tt::Registry mine = tt::base_registry();
  mine.add("wandr", [](tt::Turtle&, const tt::Params&) {});
  CHECK(tw::parse_scene(text, "w.json", mine).programs[2].controller == "wandr");
}

TEST_CASE("bad turtle entries name their JSON path") {
  CHECK_ERROR(world(R"({"id": "t"})"), "/turtles", "turtles must be a JSON array ([...]), got an object");
  CHECK_ERROR(world(R"([7])"), "/turtles/0", "a turtle must be a JSON object");
  CHECK_ERROR(world(R"([{"pos": [1, 1]}])"), "/turtles/0", "a turtle needs \"id\"");
  CHECK_ERROR(world(R"([{"id": "t"}])"), "/turtles/0", "a turtle needs \"pos\"");
  CHECK_ERROR(one(R"(, "headng": 90)"), "/turtles/0/headng", "unknown key \"headng\" in a turtle; did you mean \"heading\"?");
  CHECK_ERROR(one(R"(, "heading": "north")"), "/turtles/0/heading", "expected a number, got a string");
  CHECK_ERROR(one(R"(, "pos": [1])"), "/turtles/0/pos", "expected [x, y]");
  CHECK_ERROR(one(R"(, "radius": -1)"), "/turtles/0/radius", "radius must be > 0 (got -1)");
  CHECK_ERROR(one(R"(, "speed": 0)"), "/turtles/0/speed", "speed (units/s) must be > 0 (got 0)");
  CHECK_ERROR(one(R"(, "turn_rate": -90)"), "/turtles/0/turn_rate", "turn_rate (degrees/s) must be > 0 (got -90)");
  CHECK_ERROR(one(R"(, "bounce": 1.5)"), "/turtles/0/bounce", "bounce must be in [0, 1] (got 1.5)");
  CHECK_ERROR(one(R"(, "bounce": true)"), "/turtles/0/bounce", "expected a number");
  CHECK_ERROR(one(R"(, "controller": 3)"), "/turtles/0/controller", "expected a string, got a number");
  CHECK_ERROR(one(R"(, "params": [1, 2])"), "/turtles/0/params", "params must be a JSON object");
  CHECK_ERROR(one(R"(, "pen": "sideways")"), "/turtles/0/pen", "pen must be \"up\", \"down\", \"wall\" (down, laying walls), true (down) or false (up), got \"sideways\"");
  CHECK_ERROR(one(R"(, "pen": 1)"), "/turtles/0/pen", "got a number");
  CHECK_ERROR(one(R"(, "gps": "yes")"), "/turtles/0/gps", "expected true or false, got a string");
}

TEST_CASE("bad sensor arcs name their JSON path") {
  CHECK_ERROR(one(R"(, "sensors": 0)"), "/turtles/0/sensors", "a sensor count must be from 1 to 64 (got 0)");
  CHECK_ERROR(one(R"(, "sensors": 1000)"), "/turtles/0/sensors", "a sensor count must be from 1 to 64");
  CHECK_ERROR(one(R"(, "sensors": 2.5)"), "/turtles/0/sensors", "expected an integer >= 0, got 2.5");
  CHECK_ERROR(one(R"(, "sensors": "four")"), "/turtles/0/sensors", "sensors must be a count");
  CHECK_ERROR(one(R"(, "sensors": [])"), "/turtles/0/sensors", "a turtle needs at least one sensor");
  CHECK_ERROR(one(R"(, "sensors": [{"name": "a", "from": 45, "to": 45}])"), "/turtles/0/sensors/0",
              "sensor \"a\" covers [45, 45) degrees; need from < to <= from + 360");
  CHECK_ERROR(one(R"(, "sensors": [{"name": "a", "from": 0, "to": 90}, {"name": "b", "from": 90, "to": -90}])"),
              "/turtles/0/sensors/1", "sensor \"b\" covers [90, -90)");
  CHECK_ERROR(one(R"(, "sensors": [{"name": "all", "from": 0, "to": 361}])"), "/turtles/0/sensors/0", "need from < to <= from + 360");
  CHECK_ERROR(one(R"(, "sensors": [{"from": 0, "to": 90}])"), "/turtles/0/sensors/0", "a sensor arc needs \"name\"");
  CHECK_ERROR(one(R"(, "sensors": [{"name": "a", "to": 90}])"), "/turtles/0/sensors/0", "a sensor arc needs \"from\"");
  CHECK_ERROR(one(R"(, "sensors": [{"name": "a", "from": 0, "to": 90}, {"name": "a", "from": 90, "to": 180}])"),
              "/turtles/0/sensors/1/name", "duplicate sensor name \"a\"");
  CHECK_ERROR(one(R"(, "sensors": [{"name": "", "from": 0, "to": 90}])"), "/turtles/0/sensors/0/name", "must not be empty");
  CHECK_ERROR(one(R"(, "sensors": [{"name": "a", "from": 0, "to": 90, "width": 3}])"), "/turtles/0/sensors/0/width",
              "unknown key \"width\" in a sensor arc");
  // One whole-circle sensor is fine.
  CHECK(parse(one(R"(, "sensors": [{"name": "all", "from": 0, "to": 360}])")).programs[0].sensors.size() == 1);
}

TEST_CASE("turtles share ids with walls and balls, and sim::validate's problems map to /turtles/K") {
  CHECK_ERROR(world(R"([{"id": "b", "pos": [100, 100]}])", R"(, "balls": [{"id": "b", "pos": [300, 200], "radius": 2}])"),
              "/turtles/0/id", "duplicate id \"b\" (already used at /balls/0/id)");
  CHECK_ERROR(world(R"([{"id": "a", "pos": [100, 100]}, {"id": "a", "pos": [200, 100]}])"), "/turtles/1/id",
              "duplicate id \"a\"");
  CHECK_ERROR(world(R"([{"id": "arena-top", "pos": [100, 100]}])"), "/turtles/0/id", "taken by an arena wall");
  {
    const tw::WorldFileError e = error_of(world(R"([{"id": "a", "pos": [100, 100]}, {"id": "b", "pos": [115, 100]}])"));
    INFO(e.what());
    CHECK(e.json_path.starts_with("/turtles/"));
    CHECK(contains(e.reason, "turtle"));
    CHECK(contains(e.reason, "overlap"));
  }
  {
    const tw::WorldFileError e = error_of(one(R"(, "pos": [5, 100])"));
    INFO(e.what());
    CHECK(e.json_path == "/turtles/0/pos");
    CHECK(contains(e.reason, "sticks out of the arena walls"));
  }
  {
    const tw::WorldFileError e =
        error_of(world(R"([{"id": "a", "pos": [100, 100]}])", R"(, "walls": [{"id": "w", "from": [105, 0], "to": [105, 300]}])"));
    INFO(e.what());
    CHECK(e.json_path.starts_with("/turtles/0"));
  }
}

TEST_CASE("a gas is placed around the turtles") {
  const tw::Scene s = parse(world(R"([{"id": "a", "pos": [100, 100], "radius": 30}, {"id": "b", "pos": [300, 200], "radius": 40}])",
                                  R"(, "gas": [{"count": 400, "radius": 4, "speed": 10}])"));
  REQUIRE(s.def.balls.size() == 400);
  for (const sim::BallDef& b : s.def.balls)
    for (const sim::TurtleDef& t : s.def.turtles) {
      INFO(b.id << " and " << t.id);
      CHECK(sim::norm(b.pos - t.pos) >= b.radius + t.radius);
    }
  CHECK_FALSE(sim::validate(s.def).has_value());
}

TEST_CASE("the shipped turtle worlds load, each with the controller it shows") {
  const std::pair<const char*, const char*> worlds[] = {
      {"worlds/wander.json", "wander"}, {"worlds/wall_follower.json", "wall_follower"}, {"worlds/spiral.json", "spiral"},
      {"worlds/square.json", "square"}, {"worlds/script.json", "script"},               {"worlds/mixed.json", "wander"}};
  for (const auto& [file, controller] : worlds) {
    INFO(file);
    const tw::Scene s = tw::load_scene(std::string(TURTLEGAS_SOURCE_DIR) + "/" + file, registry());
    REQUIRE_FALSE(s.def.turtles.empty());
    REQUIRE(s.programs.size() == s.def.turtles.size());
    for (const tt::TurtleProgram& p : s.programs) CHECK(p.controller == controller);
    CHECK_FALSE(sim::validate(s.def).has_value());
    CHECK(tw::load_world_file(std::string(TURTLEGAS_SOURCE_DIR) + "/" + file).turtles.size() == s.def.turtles.size());
  }
}
