// SPDX-License-Identifier: MIT
// `turtlegas check` and `run` of 3-D worlds (docs/worlds.md, "3-D worlds"): the outputs' shapes,
// a closed-form contact through the whole path, and the loader's errors with their JSON paths.
#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>

#include <nlohmann/json.hpp>

#include "run_cli.hpp"

using namespace turtlegas::test;

TEST_CASE("run of a 3-D world: an edge contact at its closed-form time, named by the wall's id") {
  TempDir dir;
  // The edge case of world3d_test, through the file and the log: contact at t = 2, edge 0.
  const auto world = dir.write("edge.json", R"({"format": "turtlegas-world/1", "dimensions": 3,
    "arena": {"width": 20, "height": 20, "depth": 20},
    "walls": [{"id": "tri", "corners": [[0, 10, 10], [10, 10, 10], [5, 0, 10]]}],
    "balls": [{"id": "s", "pos": [5, 13, 12], "vel": [0, -1, -1], "radius": 1}]})");
  const auto r = run(dir, {"run", world.string(), "--until", "3", "--events", (dir.path / "e.jsonl").string(),
                           "--state-out", (dir.path / "s.json").string(), "--stats-json", (dir.path / "st.json").string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  std::istringstream lines(read(dir.path / "e.jsonl"));
  std::string line;
  REQUIRE(std::getline(lines, line));
  const auto e = nlohmann::json::parse(line);
  CHECK(e["kind"] == "ball-wall-edge");
  CHECK(e["a"] == "s");
  CHECK(e["b"] == "tri");
  CHECK(std::abs(e["t"].get<double>() - 2.0) < 1e-12);
  CHECK(!std::getline(lines, line));
  const auto s = nlohmann::json::parse(read(dir.path / "s.json"));
  REQUIRE(s["balls"].size() == 1);
  REQUIRE(s["balls"][0]["pos"].size() == 3);
  CHECK(std::abs(s["balls"][0]["pos"][1].get<double>() - 12.0) < 1e-12);  // y = 10 + 1 * (3 - 2) + 1
  CHECK(std::abs(s["balls"][0]["vel"][2].get<double>() + 1.0) < 1e-12);
  const auto st = nlohmann::json::parse(read(dir.path / "st.json"));
  CHECK(st["collisions"] == 1);
  CHECK(st["energy_start"] == st["energy_end"]);
}

TEST_CASE("run of a 3-D world with restitution: the scene's e, a ball's own, a wall's, in closed form") {
  TempDir dir;
  // Sphere a (the scene's e = 0.5) falls onto the shelf (e = 0.8) with normal speed 2: it leaves
  // at 2 * 0.5 * 0.8 = 0.8 after t = 2.5. Sphere b (its own e = 1) meets the elastic arena floor: it leaves at 2.
  const auto world = dir.write("e.json", R"({"format": "turtlegas-world/1", "dimensions": 3,
    "arena": {"width": 20, "height": 20, "depth": 20, "boundary": "walls"},
    "effects": {"restitution": 0.5, "tc": 0.001},
    "walls": [{"id": "shelf", "corners": [[2, 2, 1], [8, 2, 1], [8, 8, 1], [2, 8, 1]], "restitution": 0.8}],
    "balls": [{"id": "a", "pos": [5, 5, 7], "vel": [0, 0, -2], "radius": 1},
              {"id": "b", "pos": [15, 15, 5], "vel": [0, 0, -2], "radius": 1, "restitution": 1}]})");
  const auto r = run(dir, {"run", world.string(), "--until", "2.6", "--events", (dir.path / "e.jsonl").string(),
                           "--state-out", (dir.path / "s.json").string(), "--stats-json", (dir.path / "st.json").string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  const auto s = nlohmann::json::parse(read(dir.path / "s.json"));
  CHECK(std::abs(s["balls"][0]["vel"][2].get<double>() - 0.8) < 1e-12);
  CHECK(std::abs(s["balls"][1]["vel"][2].get<double>() - 2.0) < 1e-12);
  const auto st = nlohmann::json::parse(read(dir.path / "st.json"));
  CHECK(st["collisions"] == 2);
  // a loses (1 - 0.4^2) / 2 * 4 = 1.68 of kinetic energy; b nothing.
  CHECK(std::abs(st["energy_start"].get<double>() - st["energy_end"].get<double>() - 1.68) < 1e-12);
}

TEST_CASE("check and run of worlds/gas3d_box.json") {
  TempDir dir;
  auto r = run(dir, {"check", "worlds/gas3d_box.json"});
  CHECK(r.code == 0);
  CHECK(contains(r.out, "3-D, 601 balls, 8 walls"));
  r = run(dir, {"run", "worlds/gas3d_box.json", "--until", "2", "--stats-json", (dir.path / "st.json").string()});
  REQUIRE(r.code == 0);
  const auto st = nlohmann::json::parse(read(dir.path / "st.json"));
  CHECK(st["collisions"].get<double>() > 100);
  CHECK(std::abs(st["energy_end"].get<double>() - st["energy_start"].get<double>()) < 1e-11 * st["energy_start"].get<double>());
  CHECK(st["max_overlap"].get<double>() < 1e-9);
  // The start overlaps nothing either: the gas is placed clear of the walls (before: a sphere
  // started 0.86 of a radius into the shelf, and the loader let it).
  r = run(dir, {"run", "worlds/gas3d_box.json", "--until", "0", "--stats-json", (dir.path / "st0.json").string()});
  REQUIRE(r.code == 0);
  CHECK(nlohmann::json::parse(read(dir.path / "st0.json"))["max_overlap"].get<double>() < 1e-9);
}

TEST_CASE("3-D world file errors name the JSON path and the fix, exit 2") {
  TempDir dir;
  struct Case { const char* text; const char* says; };
  const Case cases[] = {
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10}})", "/arena: a 3-D arena needs \"depth\""},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "balls": [{"id": "a", "pos": [1, 2], "radius": 1}]})",
       "/balls/0/pos"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "walls": [{"id": "w", "corners": [[1, 1, 1], [2, 2, 2], [3, 3, 3]]}]})",
       "collinear"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "walls": [{"id": "w", "corners": [[1, 1, 1], [5, 1, 1], [2, 2, 1], [1, 5, 1]]}]})",
       "not convex"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "turtles": []})", "turtles stay in the plane"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "effects": {"magnetic": 1}})", "/effects/magnetic"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "effects": {"restitution": 1.5}})",
       "/effects/restitution: restitution must be in [0, 1]"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "balls": [{"id": "a", "pos": [5, 5, 5], "radius": 1, "restitution": -0.1}]})",
       "/balls/0/restitution"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "walls": [{"id": "w", "corners": [[1, 1, 5], [9, 1, 5], [5, 9, 5]], "restitution": 2}]})",
       "/walls/0/restitution"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "effects": {"tc": -1}})", "/effects/tc"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "balls": [{"id": "a", "pos": [5, 5, 5], "radius": 1}, {"id": "b", "pos": [6.5, 5, 5], "radius": 1}]})",
       "sphere 0 and sphere 1 overlap"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "walls": [{"id": "w", "corners": [[1, 1, 5], [9, 1, 5], [5, 9, 5]]}], "balls": [{"id": "a", "pos": [5, 5, 5.5], "radius": 1}]})",
       "sphere 0 overlaps wall 0"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10, "boundary": "walls"}, "balls": [{"id": "a", "pos": [0.5, 5, 5], "radius": 1}]})",
       "overlaps the arena's walls"},
  };
  for (const Case& c : cases) {
    const auto world = dir.write("bad.json", c.text);
    const auto r = run(dir, {"check", world.string()});
    INFO(c.text << "\n" << r.err);
    CHECK(r.code == 2);
    CHECK(contains(r.err, c.says));
  }
}
