// SPDX-License-Identifier: MIT
// Line cameras end to end: the world file's `"camera"` sense and `"colour"` keys (and their errors
// at JSON paths), Turtle::camera against closed forms (a wall ahead: d at the centre pixel,
// d / cos(bearing) off it), the colours and ids of a wall, a ball and a turtle, the background past
// the range, the layers (a glass wall and a ghost turtle unseen), a mirrored program's image
// (pixel order reversed), the script's ["camera", NAME] and its `sense` event with colours.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "file_errors.hpp"

#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/world_server.hpp"
#include "turtlegas/world/entries.hpp"
#include "turtlegas/world/scene.hpp"
#include "turtlegas/world/world_file.hpp"

namespace tw = turtlegas::world;
namespace tt = turtlegas::turtle;

using turtlegas::test::contains;

namespace {

const tt::Registry& registry() {
  static const tt::Registry r = turtlegas::controllers::builtin_registry();
  return r;
}

std::string world(const std::string& rest) {
  return R"({"format": "turtlegas-world/1", "arena": {"width": 400, "height": 300, "boundary": "walls"}, )" + rest + "}";
}
std::string one(const std::string& keys) { return world(R"("turtles": [{"id": "t", "pos": [100, 100])" + keys + "}]"); }

tw::Scene parse(const std::string& text) { return tw::parse_scene(text, "w.json", registry()); }
tw::WorldFileError error_of(const std::string& text) { return turtlegas::test::error_of(parse, text); }

constexpr double pi = 3.14159265358979323846;

/// Runs `scene` to 0.5 s with turtle 0's controller replaced by `program`; returns the event log.
std::vector<tt::LogEvent> run_with(const tw::Scene& scene, tt::Controller program) {
  tt::Registry reg = turtlegas::controllers::builtin_registry();
  reg.add("reader", std::move(program));
  std::vector<tt::TurtleProgram> programs = scene.programs;
  programs[0].controller = "reader";
  tw::Scene s = scene;
  s.programs = programs;
  auto server = tw::make_server(s, reg, {});
  std::vector<tt::LogEvent> log;
  server->set_event_log(&log);
  server->run_until(0.5);
  return log;
}

}  // namespace

TEST_CASE("camera: pixels from the world file, centred on their slices of the fov", "[camera]") {
  const tw::Scene s = parse(one(R"(, "senses": [
      {"name": "cam", "camera": {"pixels": 4, "fov": 60, "range": 200}},
      {"name": "side", "bearing": 90, "camera": {"pixels": 1, "fov": 10, "range": 50, "background": "Black"}},
      {"name": "ir", "ring": 2, "range": 40}])"));
  const auto& senses = s.programs[0].senses;
  REQUIRE(senses.size() == 3);
  // bearing - fov/2 + (k + 1/2) fov/n: -22.5, -7.5, 7.5, 22.5.
  CHECK(senses[0].camera);
  CHECK(senses[0].bearings == std::vector<double>{-22.5, -7.5, 7.5, 22.5});
  CHECK(senses[0].range == 200);
  CHECK(senses[0].background == "#ffffff");
  CHECK(senses[1].bearings == std::vector<double>{90});
  CHECK(senses[1].background == "#000000");
  CHECK_FALSE(senses[2].camera);
  CHECK(senses[2].background == "#ffffff");
}

TEST_CASE("colour keys on walls, balls and turtles: hex or a name, lower-cased; defaults per kind", "[camera]") {
  const tw::Scene s = parse(world(R"("walls": [{"id": "w", "from": [50, 50], "to": [50, 250], "colour": "#E15759"},
                                              {"id": "plain", "from": [60, 50], "to": [60, 250]}],
      "balls": [{"id": "b", "pos": [200, 200], "radius": 5, "colour": "orange"}],
      "turtles": [{"id": "t", "pos": [100, 100], "colour": "grey"}, {"id": "u", "pos": [300, 100]}])"));
  const tt::Colours& c = s.colours;
  CHECK(c.by_id.size() == 3);
  CHECK(c.of("wall", "w") == "#e15759");
  CHECK(c.of("wall-end", "w") == "#e15759");
  CHECK(c.of("ball", "b") == "#ffa500");
  CHECK(c.of("turtle", "t") == "#808080");
  CHECK(c.of("wall", "plain") == "#808080");
  CHECK(c.of("wall", "arena-top") == "#808080");
  CHECK(c.of("turtle", "u") == "#59a14f");
  CHECK(c.of("ball", "gas-0") == "#4e79a7");
}

TEST_CASE("camera: bad input is an error at its JSON path", "[camera]") {
  CHECK_ERROR(one(R"(, "senses": [{"name": "c", "camera": {"pixels": 0, "fov": 60, "range": 200}}])"),
              "/turtles/0/senses/0/camera/pixels", "from 1 to 100000 pixels");
  CHECK_ERROR(one(R"(, "senses": [{"name": "c", "camera": {"pixels": 100001, "fov": 60, "range": 200}}])"),
              "/turtles/0/senses/0/camera/pixels", "from 1 to 100000 pixels");
  CHECK_ERROR(one(R"(, "senses": [{"name": "c", "camera": {"pixels": 2.5, "fov": 60, "range": 200}}])"),
              "/turtles/0/senses/0/camera/pixels", "");
  CHECK_ERROR(one(R"(, "senses": [{"name": "c", "camera": {"pixels": 8, "fov": 0, "range": 200}}])"),
              "/turtles/0/senses/0/camera/fov", "fov");
  CHECK_ERROR(one(R"(, "senses": [{"name": "c", "camera": {"pixels": 8, "fov": 361, "range": 200}}])"),
              "/turtles/0/senses/0/camera/fov", "at most 360");
  CHECK_ERROR(one(R"(, "senses": [{"name": "c", "camera": {"pixels": 8, "fov": 60, "range": 0}}])"),
              "/turtles/0/senses/0/camera/range", "range");
  CHECK_ERROR(one(R"(, "senses": [{"name": "c", "camera": {"pixels": 8, "fov": 60}}])"), "/turtles/0/senses/0/camera",
              "range");
  CHECK_ERROR(one(R"(, "senses": [{"name": "c", "range": 9, "camera": {"pixels": 8, "fov": 60, "range": 200}}])"),
              "/turtles/0/senses/0/range", "inside it");
  CHECK_ERROR(one(R"(, "senses": [{"name": "c", "camera": {"pixels": 8, "fov": 60, "range": 200, "colour": "red"}}])"),
              "/turtles/0/senses/0/camera/colour", "unknown key");
  CHECK_ERROR(one(R"(, "senses": [{"name": "c", "camera": {"pixels": 8, "fov": 60, "range": 200, "background": "#12345"}}])"),
              "/turtles/0/senses/0/camera/background", "\"#rrggbb\"");
  CHECK_ERROR(one(R"(, "senses": [{"name": "c", "camera": [8, 60, 200]}])"), "/turtles/0/senses/0/camera", "");
  CHECK_ERROR(one(R"(, "senses": [{"name": "c", "ring": 4, "camera": {"pixels": 8, "fov": 60, "range": 200}}])"),
              "/turtles/0/senses/0", "not a ring and a camera at once");
  // Colours: a wall's, a ball's and a turtle's, each at its path.
  CHECK_ERROR(world(R"("walls": [{"id": "w", "from": [50, 50], "to": [50, 250], "colour": "reddish"}])"), "/walls/0/colour",
              "one of black, white");
  CHECK_ERROR(world(R"("balls": [{"id": "b", "pos": [200, 200], "radius": 5, "colour": 16711680}])"), "/balls/0/colour", "");
  CHECK_ERROR(one(R"(, "colour": "#gg0000")"), "/turtles/0/colour", "\"#rrggbb\"");
  // The script's ["camera", NAME] names a camera; a plain range sensor is not one.
  CHECK_ERROR(one(R"(, "senses": [{"name": "ir", "range": 5}], "params": {"commands": [["camera", "ir"]]})"),
              "/turtles/0/params/commands/0/1", "no camera \"ir\"");
  CHECK_ERROR(one(R"(, "params": {"commands": [["camera"]]})"), "/turtles/0/params/commands/0", "sensor's name");
  // A body spawned at run time takes its kind's default colour.
  CHECK_THROWS_AS(tw::read_ball_entry(nlohmann::json::parse(R"({"id": "b", "pos": [1, 1], "radius": 1, "colour": "red"})"), "spawn"),
                  tw::WorldFileError);
}

TEST_CASE("camera: a wall straight ahead reads d at the centre pixel and d / cos(bearing) off it", "[camera]") {
  // t at (100, 150) facing +x; a red screen on x = 100 + d. 9 pixels over 50 degrees: the centre
  // pixel looks straight ahead, pixel k along -25 + (k + 1/2) 50/9 degrees (all within the screen).
  for (const double d : {37.0, 100.0, 255.5}) {
    const std::string screen = std::to_string(100.0 + d);
    const tw::Scene s = parse(world(R"("walls": [{"id": "screen", "from": [)" + screen + R"(, 5], "to": [)" + screen +
                                    R"(, 295], "colour": "red"}],
        "turtles": [{"id": "t", "pos": [100, 150], "heading": 90,
                     "senses": [{"name": "cam", "camera": {"pixels": 9, "fov": 50, "range": 1000}}]}])"));
    std::vector<tt::Reading> px;
    const auto log = run_with(s, [&](tt::Turtle& t, const tt::Params&) { t.camera("cam", px); });
    REQUIRE(px.size() == 9);
    INFO("d = " << d);
    CHECK(px[4].bearing == 0.0);
    CHECK(std::fabs(px[4].distance - d) <= 1e-12 * d);
    for (std::size_t k = 0; k < 9; ++k) {
      const double bearing = -25.0 + (static_cast<double>(k) + 0.5) * 50.0 / 9.0;
      INFO("pixel " << k);
      CHECK(std::fabs(px[k].bearing - bearing) < 1e-12);
      CHECK(std::fabs(px[k].distance - d / std::cos(bearing * pi / 180.0)) <= 1e-12 * d);
      CHECK(px[k].what == "screen");
      CHECK(px[k].kind == "wall");
      CHECK(px[k].colour == "#ff0000");
    }
  }
}

TEST_CASE("camera: the colours and ids of a ball, a turtle and the background; a mirror reverses the image", "[camera]") {
  // t at (100, 150) facing +x, 3 pixels over 90 degrees: bearings -30, 0, 30 (30 is to its right,
  // clockwise: towards -y). Ahead a ball of radius 5 at 60 (distance 55); at 30 right a turtle of
  // radius 10 whose centre is 60 away (distance 50); at 30 left the arena's top, 300 away, past
  // the range of 250: the background.
  const double c30 = std::cos(pi / 6.0), s30 = 0.5;
  const std::string u_pos = nlohmann::json::array({100.0 + 60.0 * c30, 150.0 - 60.0 * s30}).dump();  // round-trip digits
  const tw::Scene s = parse(world(R"("balls": [{"id": "b", "pos": [160, 150], "radius": 5, "colour": "#00FF00"}],
      "turtles": [{"id": "t", "pos": [100, 150], "heading": 90, "colour": "blue",
                   "senses": [{"name": "cam", "camera": {"pixels": 3, "fov": 90, "range": 250, "background": "black"}},
                              {"name": "ir", "range": 10}]},
                  {"id": "u", "pos": )" + u_pos + R"(, "colour": "yellow"}])"));
  std::vector<tt::Reading> plain, mirrored, scanned;
  std::string not_camera;
  const auto log = run_with(s, [&](tt::Turtle& t, const tt::Params&) {
    t.camera("cam", plain);
    t.mirrored().camera("cam", mirrored);
    t.scan("cam", scanned);  // a camera's rays are range rays too
    try {
      t.camera("ir", scanned);
    } catch (const std::invalid_argument& e) {
      not_camera = e.what();
    }
  });
  REQUIRE(plain.size() == 3);
  CHECK_FALSE(plain[0].hit());
  CHECK(std::isinf(plain[0].distance));
  CHECK(plain[0].what.empty());
  CHECK(plain[0].colour == "#000000");
  CHECK(plain[1].what == "b");
  CHECK(plain[1].kind == "ball");
  CHECK(plain[1].colour == "#00ff00");
  CHECK(std::fabs(plain[1].distance - 55.0) < 1e-12);
  CHECK(plain[2].what == "u");
  CHECK(plain[2].kind == "turtle");
  CHECK(plain[2].colour == "#ffff00");
  CHECK(std::fabs(plain[2].distance - 50.0) < 1e-12);
  // Behind a mirror pixel k at bearing b looks along -b: the image is reversed, bearings as read.
  REQUIRE(mirrored.size() == 3);
  for (std::size_t k = 0; k < 3; ++k) {
    INFO("pixel " << k);
    CHECK(mirrored[k].bearing == plain[k].bearing);
    CHECK(mirrored[k].what == plain[2 - k].what);
    CHECK(mirrored[k].colour == plain[2 - k].colour);
    CHECK(mirrored[k].distance == plain[2 - k].distance);
  }
  REQUIRE(scanned.size() == 3);
  CHECK(scanned[2].colour == "#ffff00");
  CHECK(contains(not_camera, "\"ir\" is a range sensor, not a camera"));
  CHECK(contains(not_camera, "its cameras: cam"));
  // Each reading is a sense event with the colours; a range sensor's has none.
  std::vector<nlohmann::json> events;
  for (const tt::LogEvent& e : log)
    if (e.kind == "sense") events.push_back(nlohmann::json::parse("{" + e.extra + "}"));
  REQUIRE(events.size() == 3);
  CHECK(events[0]["sensor"] == "cam");
  CHECK(events[0]["hit"] == nlohmann::json::parse(R"([null, "b", "u"])"));
  CHECK(events[0]["colour"] == nlohmann::json::parse(R"(["#000000", "#00ff00", "#ffff00"])"));
  CHECK(events[1]["colour"] == nlohmann::json::parse(R"(["#ffff00", "#00ff00", "#000000"])"));
  CHECK(events[0]["range"][1] == 55);
}

TEST_CASE("camera: what the turtle's layers do not meet is not seen", "[camera]") {
  // The glass on x = 150 collides only with default and ghost: t1 (default) sees it, t2 (in its
  // own category) sees through it to the far wall; the ghost turtle at (120, 200) collides only
  // with walls, so t2's camera does not see it either.
  const tw::Scene s = parse(world(R"("walls": [
        {"id": "glass", "from": [150, 10], "to": [150, 290], "category": "walls", "collides_with": ["default", "ghost"], "colour": "cyan"},
        {"id": "far", "from": [300, 10], "to": [300, 290], "category": "walls", "colour": "magenta"}],
      "turtles": [
        {"id": "t1", "pos": [50, 100], "heading": 90, "senses": [{"name": "cam", "camera": {"pixels": 1, "fov": 1, "range": 500}}],
         "params": {"commands": [["camera", "cam"]]}},
        {"id": "t2", "pos": [50, 200], "heading": 90, "category": "t2",
         "senses": [{"name": "cam", "camera": {"pixels": 1, "fov": 1, "range": 500}}], "params": {"commands": [["camera", "cam"]]}},
        {"id": "ghost", "pos": [120, 200], "category": "ghost", "collides_with": ["walls"], "colour": "red"}])"));
  auto server = tw::make_server(s, registry(), {});
  std::vector<tt::LogEvent> log;
  server->set_event_log(&log);
  server->run_until(0.5);
  std::vector<nlohmann::json> seen;
  for (const tt::LogEvent& e : log)
    if (e.kind == "sense") seen.push_back(nlohmann::json::parse("{" + e.extra + "}"));
  REQUIRE(seen.size() == 2);
  CHECK(seen[0]["hit"] == nlohmann::json::array({"glass"}));
  CHECK(seen[0]["colour"] == nlohmann::json::array({"#00ffff"}));
  CHECK(seen[0]["range"] == nlohmann::json::array({100}));
  CHECK(seen[1]["hit"] == nlohmann::json::array({"far"}));
  CHECK(seen[1]["colour"] == nlohmann::json::array({"#ff00ff"}));
  CHECK(seen[1]["range"] == nlohmann::json::array({250}));
}

namespace {

/// The time of the first tag in worlds/tag_seeing.json with seed `seed` and t1 (who starts as
/// "it") running `controller`; `until` when there is none by then.
double first_tag(const std::string& controller, std::uint64_t seed, double until) {
  tw::Scene s = tw::load_scene(std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/tag_seeing.json", registry());
  s.def.seed = seed;
  s.programs[0].controller = controller;
  s.programs[0].params = nlohmann::json::object();
  auto server = tw::make_server(s, registry(), {});
  std::vector<tt::LogEvent> log;
  server->set_event_log(&log);
  for (double t = 1.0; t <= until; t += 1.0) {
    server->run_until(t);
    for (const tt::LogEvent& e : log)
      if (e.kind == "tag") {
        CHECK(e.a == "t1");
        return e.t;
      }
  }
  return until;
}

}  // namespace

TEST_CASE("worlds/tag_seeing.json: the seeing chaser tags sooner than the blindfold one", "[camera][tag]") {
  // Same room, same seeds, same other players: only t1's controller differs. Measured (24 seeds,
  // 120 s): seeing 3.2 to 10.0 s, mean 8.9 s; blindfold 5.1 to 120 s (no tag), mean 32.8 s; the
  // seeing chaser first in 20 of 24. The bounds below leave a wide margin on each.
  constexpr double until = 120.0;
  constexpr int seeds = 24;
  double seeing = 0.0, blind = 0.0, slowest_seeing = 0.0;
  int seeing_first = 0;
  for (std::uint64_t seed = 1; seed <= seeds; ++seed) {
    const double a = first_tag("tag_seeing", seed, until), b = first_tag("tag_chaser", seed, until);
    INFO("seed " << seed << ": seeing " << a << " s, blindfold " << b << " s");
    CHECK(a < until);
    seeing += a / seeds;
    blind += b / seeds;
    slowest_seeing = std::max(slowest_seeing, a);
    seeing_first += a < b ? 1 : 0;
  }
  INFO("mean time to the first tag: seeing " << seeing << " s, blindfold " << blind << " s; seeing first in "
                                             << seeing_first << " of " << seeds);
  CHECK(slowest_seeing < 20.0);
  CHECK(seeing < 0.5 * blind);
  CHECK(seeing_first >= 16);
}
