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

TEST_CASE("run of a 3-D world with a moving wall: struck at rest, the sphere leaves at 2u; wall_work in the stats") {
  TempDir dir;
  const auto r = run(dir, {"run", "worlds/tests/moving_wall3d.json", "--until", "1.4", "--state-out",
                           (dir.path / "s.json").string(), "--stats-json", (dir.path / "st.json").string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  const auto s = nlohmann::json::parse(read(dir.path / "s.json"));
  CHECK(std::abs(s["balls"][0]["vel"][0].get<double>() + 20.0) < 1e-12);
  const auto st = nlohmann::json::parse(read(dir.path / "st.json"));
  CHECK(std::abs(st["wall_work"].get<double>() - 400.0) < 1e-9);  // m/2 (2u)^2, m = 2, u = -10
  CHECK(std::abs(st["energy_end"].get<double>() - st["energy_start"].get<double>() - 400.0) < 1e-9);
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

TEST_CASE("run of a 3-D world with --stats: the overlap self-check samples instants and changes nothing") {
  TempDir dir;
  // --overlap-samples 3: the instants 2/3, 4/3 and the end, each every sphere against every wall
  // and (through the hashed grid) every other sphere; the run is cut there, its log unchanged.
  const auto plain = run(dir, {"run", "worlds/gas3d_box.json", "--until", "2", "--events", (dir.path / "a.jsonl").string()});
  REQUIRE(plain.code == 0);
  const auto r = run(dir, {"run", "worlds/gas3d_box.json", "--until", "2", "--overlap-samples", "3", "--events",
                           (dir.path / "b.jsonl").string(), "--stats-json", (dir.path / "st.json").string(), "--stats"});
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(read(dir.path / "a.jsonl") == read(dir.path / "b.jsonl"));
  CHECK(!read(dir.path / "a.jsonl").empty());
  const auto st = nlohmann::json::parse(read(dir.path / "st.json"));
  CHECK(st["overlap_samples"] == 3);
  CHECK(st["check_seconds"].get<double>() >= 0.0);
  CHECK(st["max_overlap"].get<double>() < 1e-9);
  CHECK(contains(r.out, "the end and 3 instants"));
  // Without --overlap-samples the budget decides; a small gas is measured at its control steps.
  const auto b = run(dir, {"run", "worlds/gas3d_box.json", "--until", "1", "--stats-json", (dir.path / "st2.json").string()});
  REQUIRE(b.code == 0);
  CHECK(nlohmann::json::parse(read(dir.path / "st2.json"))["overlap_samples"].get<int>() >= 1);
}

TEST_CASE("run --mode step of a 3-D world: the kick at each step's end, the floor met inside a step") {
  // worlds/tests/fall_step3d.json's sphere (z_n = 9 - n (n - 1) / 128 at dt = 1/16): the floor at
  // t = 2.03125 in step mode, t = 2 in exact mode (9 - 2 t^2 = 1); --dt halves the step.
  TempDir dir;
  struct Case { std::vector<std::string> mode; double t; const char* name; };
  const Case cases[] = {{{"--mode", "step"}, 2.03125, "step"},
                        {{"--mode", "exact"}, 2.0, "exact"},
                        {{}, 2.0, "exact"},
                        // dt = 1/32: z_n = 9 - n (n - 1) / 512; n = 64 (t = 2) gives z = 1.125, vz = -8.
                        {{"--mode", "step", "--dt", "0.03125"}, 2.0 + 0.125 / 8, "step"}};
  for (const Case& c : cases) {
    std::vector<std::string> args = {"run", "worlds/tests/fall_step3d.json", "--until", "2.05", "--events",
                                     (dir.path / "e.jsonl").string(), "--stats-json", (dir.path / "st.json").string()};
    args.insert(args.end(), c.mode.begin(), c.mode.end());
    const auto r = run(dir, args);
    INFO(r.err);
    REQUIRE(r.code == 0);
    const auto e = nlohmann::json::parse(read(dir.path / "e.jsonl").substr(0, read(dir.path / "e.jsonl").find('\n')));
    CHECK(e["b"] == "arena-z0");
    CHECK(std::abs(e["t"].get<double>() - c.t) < 1e-12);
    const auto st = nlohmann::json::parse(read(dir.path / "st.json"));
    CHECK(st["mode"] == c.name);
  }
  const auto r = run(dir, {"run", "worlds/tests/fall_step3d.json", "--mode", "step", "--dt", "0", "--until", "1"});
  CHECK(r.code == 2);
  CHECK(contains(r.out + r.err, "--dt"));
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
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "effects": {"magnetic": 1}})", "/effects/magnetic: in 3-D the magnetic field is a vector"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "effects": {"magnetic": [0, 1]}})",
       "/effects/magnetic: expected [x, y, z]"},
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
      // Moving walls' keys (docs/worlds.md, "Moving walls in 3-D").
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "walls": [{"id": "w", "corners": [[1, 1, 5], [9, 1, 5], [5, 9, 5]], "keys": [{"t": 1, "corners": [[1, 1, 4], [9, 1, 4], [5, 9, 3]]}]}]})",
       "/walls/0/keys/0/corners/2: a 3-D wall may only translate"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "walls": [{"id": "w", "corners": [[1, 1, 5], [9, 1, 5], [5, 9, 5]], "keys": [{"t": 2, "corners": [[1, 1, 4], [9, 1, 4], [5, 9, 4]]}, {"t": 1, "corners": [[1, 1, 3], [9, 1, 3], [5, 9, 3]]}]}]})",
       "/walls/0/keys/1/t: key times must increase"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "walls": [{"id": "w", "corners": [[1, 1, 5], [9, 1, 5], [5, 9, 5]], "keys": [{"t": 1, "corners": [[1, 1, 4], [9, 1, 4]]}]}]})",
       "/walls/0/keys/0/corners: a key lists the wall's 3 corners"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "walls": [{"id": "w", "corners": [[1, 1, 5], [9, 1, 5], [5, 9, 5]], "keys": [{"t": 1, "corners": [[1, 1, 12], [9, 1, 12], [5, 9, 12]]}]}]})",
       "/walls/0/keys/0/corners/0: the wall leaves the arena"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10, "boundary": "periodic"}, "walls": [{"id": "w", "corners": [[1, 1, 5], [9, 1, 5], [5, 9, 5]], "keys": [{"t": 1, "corners": [[1, 1, 4], [9, 1, 4], [5, 9, 4]]}]}]})",
       "/walls/0/keys: moving walls are not supported in a periodic arena"},
      {R"({"dimensions": 3, "arena": {"width": 10, "height": 10, "depth": 10}, "walls": [{"id": "w", "corners": [[1, 1, 5], [9, 1, 5], [5, 9, 5]], "keys": [{"t": 0, "corners": [[1, 1, 4], [9, 1, 4], [5, 9, 4]]}]}]})",
       "/walls/0/keys/0/t"},
  };
  for (const Case& c : cases) {
    const auto world = dir.write("bad.json", c.text);
    const auto r = run(dir, {"check", world.string()});
    INFO(c.text << "\n" << r.err);
    CHECK(r.code == 2);
    CHECK(contains(r.err, c.says));
  }
}

TEST_CASE("test of a 3-D world: a wrong expectation fails naming its entry and the values seen") {
  TempDir dir;
  // The box bounce's sphere meets arena-x1 at t = 2, 10, 18; each wrong entry below must fail.
  const auto world = dir.write("bad.json", R"({"format": "turtlegas-world/1", "dimensions": 3,
    "arena": {"width": 10, "height": 10, "depth": 10, "boundary": "walls"},
    "balls": [{"id": "s", "pos": [5, 5, 5], "vel": [2, 1, 0.5], "radius": 1}],
    "expect": [{"until": 19}, {"count": "ball-wall", "b": "arena-x1", "min": 4},
               {"near": [7, 8, 3.5], "who": "s", "within": 1e-9},
               {"near": [7, 8, 3.6], "who": "s", "within": 1e-3},
               {"velocity": [2, 1, -0.5], "who": "s", "within": 1e-9, "at": 19},
               {"event": "ball-wall", "b": "arena-z0"},
               {"no_event": "ball-wall", "b": "arena-y1"},
               {"inside": [[1, 1, 1], [9, 9, 8]]}]})");
  const auto r = run(dir, {"test", world.string()});
  INFO(r.out << r.err);
  CHECK(r.code == 1);
  CHECK(contains(r.out, "FAIL"));
  CHECK(contains(r.out, "expect[1] count ball-wall b arena-x1 = 3, wanted >= 4"));
  CHECK(!contains(r.out, "expect[2]"));
  CHECK(contains(r.out, "expect[3] near [7, 8, 3.6]: s is at [7, 8, 3.5"));
  CHECK(contains(r.out, "expect[4] velocity [2, 1, -0.5]: s moves at [-2, 1, -0.5"));
  CHECK(contains(r.out, "expect[5] event ball-wall b arena-z0: none happened"));
  CHECK(contains(r.out, "expect[6] no_event ball-wall b arena-y1: 1 happened, the first at t = 4"));
  CHECK(contains(r.out, "expect[7] inside"));
}

TEST_CASE("test of 3-D worlds: the project's pass, and bad entries are errors at their JSON path") {
  TempDir dir;
  auto r = run(dir, {"test", "worlds/tests/box_bounce3d.json", "worlds/tests/edge_corner3d.json"});
  INFO(r.out << r.err);
  CHECK(r.code == 0);
  CHECK(contains(r.out, "PASS worlds/tests/box_bounce3d.json (3-D, 18 assertions"));
  struct Case { const char* expect; const char* says; };
  const Case cases[] = {
      {R"([{"until": 1}, {"count": "ball-wal", "min": 1}])", "/expect/1/count: \"ball-wal\" is not an event of a 3-D world"},
      {R"([{"until": 1}, {"near": [1, 2], "who": "s", "within": 1}])", "/expect/1/near: expected [x, y, z]"},
      {R"([{"until": 1}, {"near": [1, 2, 3], "who": "nobody", "within": 1}])", "/expect/1/who: no ball has the id \"nobody\""},
      {R"([{"until": 1}, {"heading": 90, "who": "s"}])", "/expect/1: no assertion kind; a 3-D expectation names one of"},
      {R"([{"until": 1}, {"mode": "fast"}])", "/expect/1/mode: mode must be \"exact\", \"step\" or \"both\""},
      {R"([{"until": 1}, {"count": "exit", "min": 1, "mx": 2}])", "/expect/1/mx: unknown key \"mx\" in a \"count\""},
      {R"([{"count": "exit", "min": 1}])", "no {\"until\": T}"},
  };
  for (const Case& c : cases) {
    const auto world = dir.write("e.json", std::string(R"({"format": "turtlegas-world/1", "dimensions": 3,
      "arena": {"width": 10, "height": 10, "depth": 10}, "balls": [{"id": "s", "pos": [5, 5, 5], "radius": 1}],
      "expect": )") + c.expect + "}");
    r = run(dir, {"test", world.string()});
    INFO(c.expect << "\n" << r.out << r.err);
    CHECK(r.code == 2);
    CHECK(contains(r.out + r.err, c.says));
  }
}

TEST_CASE("run --observe of a 3-D world: the observables in three dimensions") {
  TempDir dir;
  const auto out = dir.path / "o.json";
  auto r = run(dir, {"run", "worlds/gas3d_box.json", "--until", "3", "--observe", out.string(), "--observe-from", "1"});
  INFO(r.err);
  REQUIRE(r.code == 0);
  const auto o = nlohmann::json::parse(read(out));
  CHECK(o["dimensions"] == 3);
  CHECK(o["volume"].get<double>() == 60.0 * 60.0 * 60.0);
  CHECK(o["summary"]["number_density"]["mean"].get<double>() == Approx(601.0 / 216000.0));
  CHECK(o["summary"]["collision_rate"]["mean"].get<double>() > 0.0);
  CHECK(o["speed_histogram"].contains("maxwell"));
  // The walls' pressure, per face of the box, under the world file's ids (before: not reported).
  CHECK(o["summary"]["pressure_walls"]["mean"].get<double>() > 0.0);
  REQUIRE(o["walls"].size() == 8);  // the file's triangle and shelf, then the box's six faces
  CHECK(o["walls"][0]["id"] == "triangle");
  CHECK(o["walls"][2]["id"] == "arena-x0");
  CHECK(o["walls"][7]["id"] == "arena-z1");
  CHECK(o["walls"][2]["area"].get<double>() == Approx(3600.0));
  r = run(dir, {"run", "worlds/gas3d_box.json", "--until", "3", "--observe", out.string(), "--events",
                (dir.path / "e.jsonl").string()});
  CHECK(r.code == 2);
  CHECK(contains(r.err, "--observe and --events of a 3-D world"));
}

TEST_CASE("sweep of a 3-D world: stats, observables and the expect list per run") {
  TempDir dir;
  const auto out = dir.path / "r.jsonl";
  const auto r = run(dir, {"sweep", "worlds/sweeps/gas3d_density.json", "--out", out.string(), "--jobs", "1"});
  INFO(r.out << r.err);
  REQUIRE(r.code == 0);
  std::istringstream lines(read(out));
  std::string line;
  REQUIRE(std::getline(lines, line));  // the header
  int runs = 0;
  double rate[2] = {0, 0};
  while (std::getline(lines, line)) {
    const auto j = nlohmann::json::parse(line);
    CHECK(j["stats"]["dimensions"] == 3);
    CHECK(j["stats"]["collisions"].get<double>() > 0);
    CHECK(std::abs(j["stats"]["energy_end"].get<double>() / j["stats"]["energy_start"].get<double>() - 1) < 1e-12);
    CHECK(j["expect"]["assertions"] == 7);
    if (runs >= 2) CHECK(j["expect"]["passed"] == true);  // 300 spheres: the test world itself
    rate[runs / 2] += j["observables"]["summary"]["collision_rate"]["mean"].get<double>() / 2;
    ++runs;
  }
  CHECK(runs == 4);
  // Twice the spheres in the same box: the collision rate per sphere about doubles (n sigma^2 v,
  // with chi a little above 1).
  CHECK(rate[1] / rate[0] > 1.7);
  CHECK(rate[1] / rate[0] < 2.6);
}

TEST_CASE("render of a 3-D world: seen along -z, the nearer sphere drawn last and lighter") {
  TempDir dir;
  const auto world = dir.write("two.json", R"({"format": "turtlegas-world/1", "dimensions": 3,
    "arena": {"width": 20, "height": 10, "depth": 10},
    "balls": [{"id": "near", "pos": [5, 5, 8], "vel": [1, 0, 0], "radius": 1},
              {"id": "far", "pos": [15, 5, 2], "vel": [0, 1, 0], "radius": 2}]})");
  const auto svg = dir.path / "p.svg";
  auto r = run(dir, {"render", world.string(), "--at", "2", "--out", svg.string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  const std::string text = read(svg);
  const auto near_at = text.find(R"(<circle cx="7" cy="5" r="1")");   // moved 2 along x
  const auto far_at = text.find(R"(<circle cx="15" cy="7" r="2")");   // moved 2 along y
  REQUIRE(near_at != std::string::npos);
  REQUIRE(far_at != std::string::npos);
  CHECK(far_at < near_at);  // the far one first, under the near one
  CHECK(contains(text, "width=\"800\" height=\"400\""));
  const auto png = dir.path / "p.png";
  r = run(dir, {"render", world.string(), "--at", "2", "--out", png.string()});
  REQUIRE(r.code == 0);
  CHECK(read(png).substr(1, 3) == "PNG");
  r = run(dir, {"render", world.string(), "--frames", (dir.path / "f").string(), "--from", "0", "--to", "1"});
  CHECK(r.code == 2);
  // A moving wall is drawn where it is: moving_wall3d.json's square at x = 18 - 10 t, at t = 1 at 8.
  r = run(dir, {"render", "worlds/tests/moving_wall3d.json", "--at", "1", "--out", svg.string()});
  REQUIRE(r.code == 0);
  CHECK(contains(read(svg), R"(<polygon points="8,5 8,15 8,15 8,5 ")"));
}

TEST_CASE("run of a 3-D sphere in a slot exactly its width: wedged, logged, booked; a runaway stops at --max-events") {
  TempDir dir;
  // Before the wedge rule the slot bounced at t = 0 for ever and run never returned.
  const auto slot = dir.write("slot.json", R"({"format": "turtlegas-world/1", "dimensions": 3, "name": "slot",
    "arena": {"width": 20, "height": 10, "depth": 2, "boundary": "walls"},
    "balls": [{"id": "s", "pos": [5, 5, 1], "vel": [1, 0.5, 0.3], "radius": 1}]})");
  const auto r = run(dir, {"run", slot.string(), "--until", "1", "--events", (dir.path / "e.jsonl").string(),
                           "--stats-json", (dir.path / "st.json").string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  std::istringstream lines(read(dir.path / "e.jsonl"));
  std::string line;
  REQUIRE(std::getline(lines, line));
  const auto e = nlohmann::json::parse(line);
  CHECK(e["kind"] == "wedged");
  CHECK(e["a"] == "s");
  CHECK(e["t"] == 0.0);
  CHECK(((e["b"] == "arena-z1" && e["c"] == "arena-z0") || (e["b"] == "arena-z0" && e["c"] == "arena-z1")));
  const auto st = nlohmann::json::parse(read(dir.path / "st.json"));
  CHECK(st["wedged"] == 1);
  CHECK(std::abs(st["energy_wedged"].get<double>() - 0.045) < 1e-15);
  CHECK(!st.contains("stopped"));
  // Two spheres filling a box along x (a jammed row, not covered in 3-D) run at t = 0 for ever:
  // --max-events stops the run inside its first chunk, outputs written, exit 3.
  const auto row = dir.write("row.json", R"({"format": "turtlegas-world/1", "dimensions": 3, "name": "row",
    "arena": {"width": 4, "height": 10, "depth": 10, "boundary": "walls"},
    "balls": [{"id": "a", "pos": [1, 5, 5], "vel": [1, 0, 0], "radius": 1}, {"id": "b", "pos": [3, 5, 5], "radius": 1}]})");
  const auto stopped = run(dir, {"run", row.string(), "--until", "1", "--max-events", "20000", "--stats-json",
                                 (dir.path / "row.json.stats").string()});
  INFO(stopped.err);
  CHECK(stopped.code == 3);
  CHECK(stopped.err.find("stopped at t = 0 s of 1 (max-events)") != std::string::npos);
  const auto rs = nlohmann::json::parse(read(dir.path / "row.json.stats"));
  CHECK(rs["stopped"] == "max-events");
  CHECK(rs["events"] == 20000);
}
