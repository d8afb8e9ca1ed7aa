// SPDX-License-Identifier: MIT
// Range sensors end to end: the world file's `senses` (rays, rings, lidars and their errors at
// JSON paths), Turtle::range and Turtle::scan against closed forms, a mirrored program's view,
// the `sense` events, and `expect` {"sense": ...} passing on worlds/tests/senses_closed_form.json
// and failing on a reading that is off by 1e-6.
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "file_errors.hpp"

#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/world_server.hpp"
#include "turtlegas/world/scenario.hpp"
#include "turtlegas/world/world_file.hpp"

namespace tw = turtlegas::world;
namespace tt = turtlegas::turtle;
namespace sim = turtlegas::sim;

using turtlegas::test::contains;

namespace {

const tt::Registry& registry() {
  static const tt::Registry r = turtlegas::controllers::builtin_registry();
  return r;
}

std::string world(const std::string& turtles) {
  return R"({"format": "turtlegas-world/1", "arena": {"width": 400, "height": 300, "boundary": "walls"}, "turtles": )" +
         turtles + "}";
}
std::string one(const std::string& keys) { return world(R"([{"id": "t", "pos": [100, 100])" + keys + "}]"); }

tw::Scene parse(const std::string& text) { return tw::parse_scene(text, "w.json", registry()); }
tw::WorldFileError error_of(const std::string& text) { return turtlegas::test::error_of(parse, text); }

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST_CASE("senses: rays, rings and lidars from the world file", "[senses]") {
  const tw::Scene s = parse(one(R"(, "senses": [
      {"name": "nose", "bearing": -10, "range": 50},
      {"name": "ir", "ring": 8, "range": 40},
      {"name": "lidar", "lidar": {"rays": 5, "fov": 180, "range": 300}},
      {"name": "all", "lidar": {"rays": 4, "fov": 360, "range": 10}, "bearing": 45}])"));
  const auto& senses = s.programs[0].senses;
  REQUIRE(senses.size() == 4);
  CHECK(senses[0].name == "nose");
  CHECK(senses[0].bearings == std::vector<double>{-10});
  CHECK(senses[0].range == 50);
  CHECK(senses[1].bearings == std::vector<double>{0, 45, 90, 135, 180, 225, 270, 315});
  CHECK(senses[2].bearings == std::vector<double>{-90, -45, 0, 45, 90});
  CHECK(senses[2].range == 300);
  CHECK(senses[3].bearings == std::vector<double>{45, 135, 225, 315});
  CHECK(parse(one("")).programs[0].senses.empty());
}

TEST_CASE("senses: bad input is an error at its JSON path", "[senses]") {
  CHECK_ERROR(one(R"(, "senses": {"name": "x"})"), "/turtles/0/senses", "must be a list of range sensors");
  CHECK_ERROR(one(R"(, "senses": [{"bearing": 0, "range": 5}])"), "/turtles/0/senses/0", "name");
  CHECK_ERROR(one(R"(, "senses": [{"name": "a", "range": 5}, {"name": "a", "range": 5}])"), "/turtles/0/senses/1/name",
              "duplicate sensor name");
  CHECK_ERROR(one(R"(, "senses": [{"name": "a", "range": -5}])"), "/turtles/0/senses/0/range", "range");
  CHECK_ERROR(one(R"(, "senses": [{"name": "a", "bearing": 0}])"), "/turtles/0/senses/0", "range");
  CHECK_ERROR(one(R"(, "senses": [{"name": "a", "ring": 0, "range": 5}])"), "/turtles/0/senses/0/ring", "from 1 to");
  CHECK_ERROR(one(R"(, "senses": [{"name": "a", "lidar": {"rays": 10, "fov": 400, "range": 5}}])"),
              "/turtles/0/senses/0/lidar/fov", "at most 360");
  CHECK_ERROR(one(R"(, "senses": [{"name": "a", "lidar": {"rays": 10, "fov": 90}}])"), "/turtles/0/senses/0/lidar", "range");
  CHECK_ERROR(one(R"(, "senses": [{"name": "a", "rnage": 5}])"), "/turtles/0/senses/0/rnage", "unknown key");
  // A script's ["sense", NAME] must name one of the turtle's sensors.
  CHECK_ERROR(one(R"(, "senses": [{"name": "a", "range": 5}], "params": {"commands": [["sense", "b"]]})"),
              "/turtles/0/params/commands/0/1", "no range sensor \"b\"");
  CHECK_ERROR(one(R"(, "params": {"commands": [["sense", 3]]})"), "/turtles/0/params/commands/0", "sensor's name");
}

TEST_CASE("Turtle::range and Turtle::scan read closed forms; a mirrored program sees them mirrored", "[senses]") {
  tt::Registry reg = turtlegas::controllers::builtin_registry();
  std::vector<tt::Reading> plain, mirrored, ring;
  tt::Reading nose;
  std::string unknown;
  reg.add("reader", [&](tt::Turtle& t, const tt::Params&) {
    nose = t.range("nose");
    t.scan("ring", ring);
    t.scan("pair", plain);
    t.mirrored().scan("pair", mirrored);
    try {
      t.range("nope");
    } catch (const std::invalid_argument& e) {
      unknown = e.what();
    }
  });
  // t at (100, 150) facing +x; a ball 96 ahead (closed form 100 - sqrt(25 - 9)); a wall 50 to its
  // right (y = 100); the arena's top 150 to its left.
  const tw::Scene s = parse(R"({"format": "turtlegas-world/1", "arena": {"width": 400, "height": 300, "boundary": "walls"},
    "walls": [{"id": "w", "from": [50, 100], "to": [350, 100]}],
    "balls": [{"id": "b", "pos": [200, 153], "vel": [0, 0], "radius": 5}],
    "turtles": [{"id": "t", "pos": [100, 150], "heading": 90, "controller": "script",
                 "senses": [{"name": "nose", "bearing": 0, "range": 500}, {"name": "ring", "ring": 4, "range": 120},
                            {"name": "pair", "bearing": 90, "range": 1000}]}]})");
  std::vector<tt::TurtleProgram> programs = s.programs;
  programs[0].controller = "reader";
  tt::WorldServer server(s.def, programs, reg);
  std::vector<tt::LogEvent> log;
  server.set_event_log(&log);
  server.run_until(0.5);
  CHECK(nose.hit());
  CHECK(nose.what == "b");
  CHECK(nose.kind == "ball");
  CHECK(std::fabs(nose.distance - 96.0) < 1e-12);
  REQUIRE(ring.size() == 4);
  CHECK(ring[1].what == "w");  // right: the wall at 50
  CHECK(ring[1].distance == 50.0);
  CHECK(ring[2].what == "arena-left");
  CHECK(ring[2].distance == 100.0);
  CHECK_FALSE(ring[3].hit());  // left: the top is 150 away, past 120
  CHECK(std::isinf(ring[3].distance));
  CHECK(ring[3].bearing == 270.0);
  REQUIRE(plain.size() == 1);
  REQUIRE(mirrored.size() == 1);
  CHECK(plain[0].what == "w");  // bearing 90: right, the wall
  CHECK(mirrored[0].what == "arena-top");  // behind the mirror bearing 90 looks along 270: left
  CHECK(mirrored[0].distance == 150.0);
  CHECK(mirrored[0].bearing == 90.0);
  CHECK(contains(unknown, "no range sensor \"nope\""));
  CHECK(contains(unknown, "nose"));
  // Every reading is a sense event: the sensor, each ray's distance and what it hit (null past the range).
  std::vector<nlohmann::json> senses;
  for (const tt::LogEvent& e : log)
    if (e.kind == "sense") {
      CHECK(e.a == "t");
      CHECK(e.t == 0.0);
      senses.push_back(nlohmann::json::parse("{" + e.extra + "}"));
    }
  REQUIRE(senses.size() == 4);
  CHECK(senses[0]["sensor"] == "nose");
  CHECK(senses[0]["hit"] == nlohmann::json::array({"b"}));
  CHECK(senses[1]["sensor"] == "ring");
  CHECK(senses[1]["range"] == nlohmann::json::parse("[96, 50, 100, null]"));
  CHECK(senses[1]["hit"] == nlohmann::json::parse(R"(["b", "w", "arena-left", null])"));
  CHECK(senses[3]["hit"] == nlohmann::json::array({"arena-top"}));
}

TEST_CASE("expect {\"sense\": ...} passes on the closed-form world and fails a reading off by 1e-6", "[senses]") {
  const std::string path = std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/tests/senses_closed_form.json";
  const std::string text = read_file(path);
  REQUIRE_FALSE(text.empty());
  for (sim::Mode mode : {sim::Mode::exact, sim::Mode::step}) {
    const tw::Scene good = tw::parse_scene(text, path, registry());
    const tw::ExpectResult r = tw::run_expectations(good, registry(), mode);
    INFO((r.failures.empty() ? std::string() : r.failures.front()));
    CHECK(r.passed());
  }
  nlohmann::json doc = nlohmann::json::parse(text);
  for (auto& e : doc["expect"])
    if (e.contains("sense") && e.value("reading", 0) == 0 && e["sense"] == "front") e["range"] = {96.000001};
  const tw::Scene bad = tw::parse_scene(doc.dump(), path, registry());
  const tw::ExpectResult r = tw::run_expectations(bad, registry(), sim::Mode::exact);
  REQUIRE(r.failures.size() == 1);
  CHECK(contains(r.failures.front(), "sense front of t1, reading 0"));
  // Bounds on every ray: the ring reads 96 at the nearest.
  doc = nlohmann::json::parse(text);
  doc["expect"].push_back({{"sense", "ring"}, {"who", "t1"}, {"min", 97}});
  const tw::ExpectResult r2 = tw::run_expectations(tw::parse_scene(doc.dump(), path, registry()), registry(), sim::Mode::exact);
  REQUIRE(r2.failures.size() == 1);
  CHECK(contains(r2.failures.front(), "reads 96"));
}

TEST_CASE("sensor noise: Gaussian on the distance and dropouts, from the turtle's seeded stream", "[senses]") {
  // 4000 rays of a ring at a wall 100 away (the ring of 1 ray, read 4000 times by the program):
  // the errors have mean ~0 and standard deviation ~sd, about `dropout` of them read nothing, and
  // the same seed gives the same log, another seed another.
  const std::string text = R"({"format": "turtlegas-world/1", "seed": SEED, "arena": {"width": 400, "height": 300, "boundary": "walls"},
    "turtles": [{"id": "t", "pos": [300, 150], "heading": 90, "senses": [{"name": "nose", "range": 500, "noise": {"sd": 0.5, "dropout": 0.1}}],
                 "controller": "script", "params": {"commands": [CMDS]}}]})";
  std::string cmds;
  for (int k = 0; k < 4000; ++k) cmds += std::string(k ? ", " : "") + "[\"sense\", \"nose\"]";
  auto run = [&](int seed) {
    std::string t = text;
    t.replace(t.find("SEED"), 4, std::to_string(seed));
    t.replace(t.find("CMDS"), 4, cmds);
    const tw::Scene s = parse(t);
    tt::WorldServer server(s.def, s.programs, registry());
    std::vector<tt::LogEvent> log;
    server.set_event_log(&log);
    server.run_until(0.1);
    std::vector<nlohmann::json> out;
    for (const tt::LogEvent& e : log)
      if (e.kind == "sense") out.push_back(nlohmann::json::parse("{" + e.extra + "}")["range"][0]);
    return out;
  };
  const std::vector<nlohmann::json> a = run(5), b = run(5), c = run(6);
  REQUIRE(a.size() == 4000);
  CHECK(a == b);
  CHECK(a != c);
  double sum = 0.0, sum2 = 0.0;
  int dropped = 0, n = 0;
  for (const nlohmann::json& d : a) {
    if (d.is_null()) {
      ++dropped;
      continue;
    }
    const double e = d.get<double>() - 100.0;  // the wall x = 400 is 100 ahead
    sum += e;
    sum2 += e * e;
    ++n;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  INFO("mean " << mean << ", sd " << sd << ", dropped " << dropped);
  CHECK(std::fabs(mean) < 5 * 0.5 / std::sqrt(n));  // 5 standard errors
  CHECK(std::fabs(sd - 0.5) < 0.05);
  CHECK(std::fabs(dropped / 4000.0 - 0.1) < 5 * std::sqrt(0.1 * 0.9 / 4000));
  CHECK_ERROR(one(R"(, "senses": [{"name": "a", "range": 5, "noise": {"dropout": 1.5}}])"), "/turtles/0/senses/0/noise/dropout",
              "probability");
  CHECK_ERROR(one(R"(, "senses": [{"name": "a", "range": 5, "noise": {"sigma": 1}}])"), "/turtles/0/senses/0/noise/sigma",
              "unknown key");
}
