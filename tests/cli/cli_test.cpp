// SPDX-License-Identifier: MIT
// Runs the turtlegas program as a user would and checks exit codes, messages and output files.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "run_cli.hpp"

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace turtlegas::test;

namespace {

/// A small box with walls and a few balls: a few hundred collisions in a second.
const std::string box_world = R"({
  "format": "turtlegas-world/1", "name": "box", "seed": 3,
  "arena": {"width": 100, "height": 100, "boundary": "walls"},
  "walls": [{"id": "mid", "from": [50, 20], "to": [50, 80]}],
  "balls": [{"id": "b1", "pos": [20, 50], "vel": [30, 10], "radius": 3},
            {"id": "b2", "pos": [80, 50], "vel": [-20, 25], "radius": 4, "mass": 2}],
  "gas": [{"count": 20, "radius": 2, "speed": 40, "region": [[0, 0], [45, 100]], "id_prefix": "g"}]
})";

/// Boundary none: the ball "leaver" flies out of the arena.
const std::string open_world = R"({
  "format": "turtlegas-world/1",
  "arena": {"width": 100, "height": 100},
  "balls": [{"id": "leaver", "pos": [90, 50], "vel": [50, 0], "radius": 1},
            {"id": "stayer", "pos": [50, 50], "vel": [0, 0], "radius": 1}]
})";

}  // namespace

TEST_CASE("cli: bad input exits with 2 and says why") {
  TempDir dir;
  SECTION("invalid JSON") {
    const fs::path w = dir.write("bad.json", "{\n  \"format\": \"turtlegas-world/1\",\n  oops\n}");
    const Result r = run(dir, {"run", w.string(), "--until", "1"});
    CHECK(r.code == 2);
    CHECK(contains(r.err, "bad.json:3:3: invalid JSON"));
  }
  SECTION("unknown key") {
    const fs::path w = dir.write("unknown.json", R"({"format": "turtlegas-world/1", "bals": []})");
    const Result r = run(dir, {"check", w.string()});
    CHECK(r.code == 2);
    CHECK(contains(r.err, "unknown.json: /bals: unknown key \"bals\""));
  }
  SECTION("missing file") {
    const Result r = run(dir, {"run", (dir.path / "nope.json").string(), "--until", "1"});
    CHECK(r.code == 2);
    CHECK(contains(r.err, "nope.json: no such file"));
  }
  SECTION("bad --mode") {
    const fs::path w = dir.write("w.json", box_world);
    const Result r = run(dir, {"run", w.string(), "--until", "1", "--mode", "fast"});
    CHECK(r.code == 2);
    CHECK(contains(r.err, "--mode"));
  }
  SECTION("missing --until, no subcommand, bad numbers") {
    const fs::path w = dir.write("w.json", box_world);
    CHECK(run(dir, {"run", w.string()}).code == 2);
    CHECK(run(dir, {}).code == 2);
    CHECK(run(dir, {"run", w.string(), "--until", "soon"}).code == 2);
    const Result neg = run(dir, {"run", w.string(), "--until", "-1"});
    CHECK(neg.code == 2);
    CHECK(contains(neg.err, "--until: must be"));
    const Result dt = run(dir, {"run", w.string(), "--until", "1", "--dt", "0"});
    CHECK(dt.code == 2);
    CHECK(contains(dt.err, "--dt: must be"));
  }
  SECTION("output directory that does not exist") {
    const fs::path w = dir.write("w.json", box_world);
    const Result r = run(dir, {"run", w.string(), "--until", "1", "--events", (dir.path / "no/dir/e.jsonl").string()});
    CHECK(r.code == 2);
    CHECK(contains(r.err, "does not exist"));
    CHECK_FALSE(fs::exists(dir.path / "no"));
  }
  SECTION("a bad value in the world file") {
    const fs::path w = dir.write("neg.json", R"({"format": "turtlegas-world/1",
      "balls": [{"id": "b", "pos": [1, 1], "radius": -1}]})");
    const Result r = run(dir, {"run", w.string(), "--until", "1"});
    CHECK(r.code == 2);
    CHECK(contains(r.err, "error: " + w.string() + ": /balls/0/radius: radius must be > 0 (got -1)"));
  }
}

TEST_CASE("cli: --help exits with 0") {
  TempDir dir;
  const Result r = run(dir, {"run", "--help"});
  CHECK(r.code == 0);
  CHECK(contains(r.out, "--until"));
}

TEST_CASE("cli: check") {
  TempDir dir;
  const fs::path w = dir.write("box.json", box_world);
  const Result r = run(dir, {"check", w.string()});
  INFO(r.err);
  CHECK(r.code == 0);
  CHECK(contains(r.out, "box.json: ok"));
  CHECK(contains(r.out, "22 balls"));
  const Result shipped = run(dir, {"check", std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/gas.json"});
  CHECK(shipped.code == 0);
}

TEST_CASE("cli: check takes many files, goes on past a bad one, and counts them") {
  TempDir dir;
  const fs::path good = dir.write("box.json", box_world);
  const fs::path bad = dir.write("bad.json", R"({"format": "turtlegas-world/1", "bals": []})");
  const std::string gas = std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/gas.json";
  const Result all_good = run(dir, {"check", good.string(), gas});
  INFO(all_good.err);
  CHECK(all_good.code == 0);
  CHECK(contains(all_good.out, "box.json: ok"));
  CHECK(contains(all_good.out, "gas.json: ok"));
  CHECK(contains(all_good.out, "2 of 2 world files ok"));
  // The bad file in the middle: reported on stderr, the one after it still checked, exit 2.
  const Result one_bad = run(dir, {"check", good.string(), bad.string(), gas});
  CHECK(one_bad.code == 2);
  CHECK(contains(one_bad.err, "bad.json: /bals: unknown key \"bals\""));
  CHECK(contains(one_bad.out, "gas.json: ok"));
  CHECK(contains(one_bad.out, "2 of 3 world files ok"));
  const Result missing = run(dir, {"check", (dir.path / "nope.json").string(), good.string()});
  CHECK(missing.code == 2);
  CHECK(contains(missing.err, "nope.json: no such file"));
  CHECK(contains(missing.out, "1 of 2 world files ok"));
}

TEST_CASE("cli: --version names the version, the commit, the build type and the compiler") {
  TempDir dir;
  const Result r = run(dir, {"--version"});
  INFO(r.err);
  CHECK(r.code == 0);
  const std::string first = r.out.substr(0, r.out.find('\n'));
  CHECK(first == "turtlegas 0.1.0");
  CHECK(contains(r.out, "\ncommit "));
  CHECK_FALSE(contains(r.out, "commit \n"));
  CHECK(contains(r.out, "\nbuild "));
#if defined(__GNUC__) && !defined(__clang__)
  CHECK(contains(r.out, "GNU " + std::to_string(__GNUC__) + "."));
#endif
#if defined(NDEBUG)
  CHECK(contains(r.out, "build Release"));
#else
  CHECK(contains(r.out, "build Debug"));
#endif
}

TEST_CASE("cli: a run writes events, state and stats") {
  TempDir dir;
  const fs::path w = dir.write("box.json", box_world);
  for (const char* mode : {"exact", "step"}) {
    INFO(mode);
    const fs::path events = dir.path / (std::string(mode) + ".jsonl"), state = dir.path / "state.json",
                   stats = dir.path / "stats.json", svg = dir.path / "final.svg";
    const Result r = run(dir, {"run", w.string(), "--until", "2", "--mode", mode, "--events", events.string(),
                               "--state-out", state.string(), "--stats-json", stats.string(), "--svg", svg.string(),
                               "--stats"});
    INFO(r.err);
    REQUIRE(r.code == 0);
    CHECK(contains(r.out, "collisions"));

    // Events: JSON lines, non-decreasing in time, ids rather than indices.
    std::ifstream in(events);
    std::string line;
    double last = 0.0;
    std::size_t n = 0;
    std::set<std::string> ball_ids{"b1", "b2"}, wall_ids{"mid", "arena-bottom", "arena-right", "arena-top", "arena-left"};
    for (int i = 0; i < 20; ++i) ball_ids.insert("g" + std::to_string(i));
    while (std::getline(in, line)) {
      const json e = json::parse(line);
      const double t = e.at("t").get<double>();
      CHECK(t >= last);
      CHECK(t <= 2.0);
      last = t;
      const std::string kind = e.at("kind").get<std::string>();
      CHECK(ball_ids.count(e.at("a").get<std::string>()) == 1);
      if (kind == "ball-ball") CHECK(ball_ids.count(e.at("b").get<std::string>()) == 1);
      else if (kind == "ball-wall" || kind == "ball-wall-end") CHECK(wall_ids.count(e.at("b").get<std::string>()) == 1);
      else FAIL("unexpected kind " << kind);
      ++n;
    }
    CHECK(n > 10);

    const json s = json::parse(read(state));
    CHECK(s.at("t").get<double>() == 2.0);
    REQUIRE(s.at("balls").size() == 22);
    CHECK(s.at("balls")[0].at("id") == "b1");
    CHECK(s.at("balls")[0].at("pos").size() == 2);
    CHECK(s.at("balls")[0].at("vel").size() == 2);
    CHECK(s.at("turtles").empty());

    const json st = json::parse(read(stats));
    for (const char* key : {"collisions", "events", "wall_seconds", "energy_start", "energy_end", "max_overlap",
                            "max_overlap_relative", "ball_ball", "ball_wall", "ball_wall_end", "exits",
                            "cell_crossings", "steps", "mode", "until", "balls", "collisions_per_second"})
      CHECK(st.contains(key));
    CHECK(st.at("collisions").get<std::uint64_t>() == n);
    CHECK(st.at("mode") == mode);
    CHECK(st.at("balls") == 22);
    CHECK(std::abs(st.at("energy_end").get<double>() - st.at("energy_start").get<double>()) <=
          1e-9 * st.at("energy_start").get<double>());

    CHECK(read(svg).starts_with("<?xml"));
    // No temporary files are left behind.
    for (const auto& entry : fs::directory_iterator(dir.path)) CHECK_FALSE(contains(entry.path().string(), ".tmp-"));
  }
}

TEST_CASE("cli: --stats' collisions per second leave the overlap self-check out (issue 32)") {
  // A gas measured at 1000 instants: the samples take a good share of the wall time, which the
  // speed printed and written must not count.
  TempDir dir;
  const fs::path w = dir.write("gas.json", R"({"format": "turtlegas-world/1", "seed": 3,
    "arena": {"width": 400, "height": 400, "boundary": "walls"},
    "gas": [{"count": 3000, "radius": 2, "speed": 50, "region": [[5, 5], [395, 395]]}]})");
  const fs::path stats = dir.path / "stats.json";
  const Result r = run(dir, {"run", w.string(), "--until", "2", "--stats-json", stats.string(), "--stats",
                             "--overlap-samples", "1000"});
  INFO(r.err);
  REQUIRE(r.code == 0);
  const json st = json::parse(read(stats));
  REQUIRE(st.contains("check_seconds"));
  const double wall = st.at("wall_seconds").get<double>(), check = st.at("check_seconds").get<double>();
  CHECK(check > 0.0);
  CHECK(check < wall);
  const double collisions = st.at("collisions").get<double>();
  REQUIRE(collisions > 0.0);
  const double expected = collisions / (wall - check);
  CHECK(std::abs(st.at("collisions_per_second").get<double>() - expected) <= 1e-12 * expected);
  CHECK(contains(r.out, "self-check"));
}

TEST_CASE("cli: the same run gives the same event log, byte for byte") {
  TempDir dir;
  const fs::path w = dir.write("box.json", box_world);
  const fs::path a = dir.path / "a.jsonl", b = dir.path / "b.jsonl";
  REQUIRE(run(dir, {"run", w.string(), "--until", "3", "--events", a.string()}).code == 0);
  REQUIRE(run(dir, {"run", w.string(), "--until", "3", "--events", b.string()}).code == 0);
  CHECK(read(a) == read(b));
  CHECK_FALSE(read(a).empty());
}

TEST_CASE("cli: exits are logged without b, and exited balls leave the state") {
  TempDir dir;
  const fs::path w = dir.write("open.json", open_world);
  const fs::path events = dir.path / "e.jsonl", state = dir.path / "s.json";
  const Result r = run(dir, {"run", w.string(), "--until", "1", "--events", events.string(), "--state-out", state.string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  const json e = json::parse(read(events));  // exactly one line
  CHECK(e.at("kind") == "exit");
  CHECK(e.at("a") == "leaver");
  CHECK_FALSE(e.contains("b"));
  CHECK(e.at("t").get<double>() == Approx(0.2));
  const json s = json::parse(read(state));
  REQUIRE(s.at("balls").size() == 1);
  CHECK(s.at("balls")[0].at("id") == "stayer");
}

namespace {

/// A walled room with a wall in front of a scripted turtle, and a wanderer.
const std::string turtle_world = R"({
  "format": "turtlegas-world/1", "name": "turtles", "seed": 9,
  "arena": {"width": 300, "height": 200, "boundary": "walls"},
  "walls": [{"id": "target", "from": [200, 20], "to": [200, 180]}],
  "turtles": [
    {"id": "s", "pos": [50, 100], "heading": 90, "speed": 45, "controller": "script", "pen": "down",
     "params": {"commands": [["forward", 500], ["back", 10], ["left", 90], ["forward", 20]]}},
    {"id": "w", "pos": [250, 100], "heading": 10, "speed": 60, "controller": "wander", "sensors": 8}
  ]
})";

std::vector<json> lines_of(const fs::path& p) {
  std::vector<json> out;
  std::ifstream in(p);
  std::string line;
  while (std::getline(in, line)) out.push_back(json::parse(line));
  return out;
}

}  // namespace

TEST_CASE("cli: a turtle world logs contacts and touches, and writes turtles to the state and stats") {
  TempDir dir;
  const fs::path w = dir.write("turtles.json", turtle_world);
  for (const char* mode : {"exact", "step"}) {
    INFO(mode);
    const fs::path events = dir.path / "e.jsonl", state = dir.path / "s.json", stats = dir.path / "st.json",
                   svg = dir.path / "t.svg";
    const Result r = run(dir, {"run", w.string(), "--until", "20", "--mode", mode, "--events", events.string(),
                               "--state-out", state.string(), "--stats-json", stats.string(), "--svg", svg.string(),
                               "--stats"});
    INFO(r.err);
    REQUIRE(r.code == 0);
    CHECK(contains(r.out, "2 turtles"));
    CHECK(contains(r.out, "touches"));

    const std::vector<json> log = lines_of(events);
    double last = 0.0;
    std::size_t contacts = 0, touches = 0;
    bool s_hit_target = false, s_felt_it_in_front = false;
    for (const json& e : log) {
      const double t = e.at("t").get<double>();
      CHECK(t >= last);
      last = t;
      const std::string kind = e.at("kind");
      if (kind.starts_with("turtle-")) ++contacts;
      if (kind == "turtle-wall" && e.at("a") == "s" && e.at("b") == "target") s_hit_target = true;
      if (kind == "touch") {
        ++touches;
        REQUIRE(e.contains("sensors"));
        REQUIRE(e.contains("bearing"));
        CHECK(e.at("sensors").is_array());
        const double bearing = e.at("bearing").get<double>();
        CHECK(bearing >= 0.0);
        CHECK(bearing < 360.0);
        if (e.at("a") == "s" && e.at("b") == "target") {
          s_felt_it_in_front = e.at("sensors") == json::array({"front"}) && std::abs(bearing) < 1e-9;
          // Contact at x = 190 after 140 units at 45/s, t = 3.11 s; felt at the next boundary, 94 dt.
          CHECK(t == Approx(94.0 / 30.0));
        }
      }
    }
    CHECK(s_hit_target);
    CHECK(s_felt_it_in_front);
    CHECK(contacts > 3);
    CHECK(touches == contacts);  // each contact becomes exactly one touch at the next boundary

    const json s = json::parse(read(state));
    CHECK(s.at("balls").empty());
    REQUIRE(s.at("turtles").size() == 2);
    const json& st0 = s.at("turtles")[0];
    CHECK(st0.at("id") == "s");
    // 140 to the wall, 10 back, a left turn, 20 north.
    CHECK(st0.at("pos")[0].get<double>() == Approx(180.0));
    CHECK(st0.at("pos")[1].get<double>() == Approx(120.0));
    CHECK(std::remainder(st0.at("heading").get<double>(), 360.0) == Approx(0.0).margin(1e-9));  // north
    CHECK(st0.at("heading").get<double>() < 360.0);
    CHECK(s.at("turtles")[1].at("id") == "w");

    const json stj = json::parse(read(stats));
    for (const char* key : {"turtles", "turtle_wall", "turtle_wall_end", "turtle_turtle", "turtle_ball", "touches",
                            "faults", "turtles_finished", "collisions", "max_overlap"})
      CHECK(stj.contains(key));
    CHECK(stj.at("turtles") == 2);
    CHECK(stj.at("touches").get<std::size_t>() == touches);
    CHECK(stj.at("faults") == 0);
    CHECK(stj.at("turtles_finished") == 1);
    CHECK(stj.at("turtle_wall").get<std::size_t>() + stj.at("turtle_wall_end").get<std::size_t>() +
              stj.at("turtle_turtle").get<std::size_t>() + stj.at("turtle_ball").get<std::size_t>() ==
          contacts);

    const std::string picture = read(svg);
    CHECK(contains(picture, "class=\"turtle\""));
    CHECK(contains(picture, "class=\"trail\""));
    CHECK(contains(picture, ">w</text>"));
  }
}

TEST_CASE("cli: turtle worlds give the same event log, byte for byte") {
  TempDir dir;
  for (const char* world : {"worlds/mixed.json", "worlds/wander.json"}) {
    INFO(world);
    const std::string file = std::string(TURTLEGAS_SOURCE_DIR) + "/" + world;
    const fs::path a = dir.path / "a.jsonl", b = dir.path / "b.jsonl";
    REQUIRE(run(dir, {"run", file, "--until", "20", "--events", a.string()}).code == 0);
    REQUIRE(run(dir, {"run", file, "--until", "20", "--events", b.string()}).code == 0);
    const std::string log = read(a);
    CHECK(log == read(b));
    CHECK(contains(log, "\"kind\": \"touch\""));
  }
}

TEST_CASE("cli: turtle input errors exit with 2 and say why") {
  TempDir dir;
  SECTION("an unknown controller") {
    std::string text = turtle_world;
    text.replace(text.find("\"wander\""), 8, "\"wandr\"");
    const fs::path w = dir.write("wandr.json", text);
    for (const char* command : {"run", "check"}) {
      const Result r = command == std::string("run") ? run(dir, {"run", w.string(), "--until", "1"})
                                                     : run(dir, {"check", w.string()});
      CHECK(r.code == 2);
      CHECK(contains(r.err, w.string() + ": /turtles/1/controller: controller 'wandr' is not registered; known: braitenberg, epuck_swarm, mirror, script, "
                                         "spiral, square, tag_camera, tag_chaser, tag_evader, tag_random, tag_seeing, wall_follower, wander; "
                                         "did you mean 'wander'?"));
    }
  }
  SECTION("a typo in a script") {
    std::string text = turtle_world;
    text.replace(text.find("\"back\""), 6, "\"bakc\"");
    const fs::path w = dir.write("typo.json", text);
    const Result r = run(dir, {"run", w.string(), "--until", "1"});
    CHECK(r.code == 2);
    CHECK(contains(r.err, "/turtles/0/params/commands/1/0: unknown command 'bakc'"));
  }
  SECTION("bad runtime options") {
    const fs::path w = dir.write("t.json", turtle_world);
    const Result stack = run(dir, {"run", w.string(), "--until", "1", "--stack-kib", "1"});
    CHECK(stack.code == 2);
    CHECK(contains(stack.err, "--stack-kib: must be"));
    const Result budget = run(dir, {"run", w.string(), "--until", "1", "--program-budget", "0"});
    CHECK(budget.code == 2);
    CHECK(contains(budget.err, "--program-budget: must be"));
  }
}

TEST_CASE("cli: a param of the wrong type is refused at load time, naming its path") {
  // wander declares params.step a number (registry.hpp): a string used to pass `check` and make
  // the program throw on its first line; now the loader refuses it. A program that faults at run
  // time (its turtle stops, the fault is logged, the run goes on) is tested in cli_robust_test
  // (forward(NaN)) and world_server_test.
  TempDir dir;
  std::string text = turtle_world;
  text.replace(text.find("\"sensors\": 8"), 12, R"("params": {"step": "far"})");
  const fs::path w = dir.write("fault.json", text);
  for (const std::string command : {"check", "run"}) {
    const Result r = command == "check" ? run(dir, {"check", w.string()}) : run(dir, {"run", w.string(), "--until", "10"});
    INFO(r.err);
    CHECK(r.code == 2);
    CHECK(contains(r.err, "/params/step: step must be a number >= 0, got \"far\""));
  }
}

TEST_CASE("cli: check reports turtles and controllers; controllers lists the registry") {
  TempDir dir;
  const fs::path w = dir.write("t.json", turtle_world);
  const Result r = run(dir, {"check", w.string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(contains(r.out, "2 turtles"));
  CHECK(contains(r.out, "turtles: s, w; controllers: script, wander"));

  const Result list = run(dir, {"controllers"});
  REQUIRE(list.code == 0);
  for (const char* name : {"script", "spiral", "square", "wall_follower", "wander"}) CHECK(contains(list.out, name));
  CHECK(contains(list.out, "runs params.commands"));
}

TEST_CASE("cli: every shipped turtle world runs for a minute") {
  TempDir dir;
  for (const char* world : {"wander", "wall_follower", "spiral", "square", "script", "mixed"}) {
    INFO(world);
    const fs::path state = dir.path / "s.json";
    const fs::path stats = dir.path / "stats.json";
    const Result r = run(dir, {"run", std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/" + world + ".json", "--until", "60",
                               "--state-out", state.string(), "--stats-json", stats.string()});
    INFO(r.err);
    REQUIRE(r.code == 0);
    CHECK_FALSE(json::parse(read(state)).at("turtles").empty());
    // Nothing sinks into anything: in mixed.json balls hit moving turtles from every side.
    CHECK(json::parse(read(stats)).at("max_overlap_relative").get<double>() <= 1e-9);
  }
}

TEST_CASE("cli: --observe writes the gas observables and --svg-trails the balls' flights, the run unchanged") {
  TempDir dir;
  auto P = [&](const char* name) { return (dir.path / name).string(); };
  const std::string gas = std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/memo_gas_fields.json";
  const Result plain = run(dir, {"run", gas, "--until", "3", "--events", P("plain.jsonl")});
  REQUIRE(plain.code == 0);
  const Result r = run(dir, {"run", gas, "--until", "3", "--events", P("observed.jsonl"), "--observe", P("obs.json"),
                             "--observe-from", "1", "--observe-window", "0.5", "--observe-samples", "5", "--svg",
                             P("pic.svg"), "--svg-trails", "1", "--observe-rdf-bins", "30"});
  REQUIRE(r.code == 0);
  // Stopping at the sample times changes nothing: the same event log, byte for byte.
  CHECK(read(dir.path / "observed.jsonl") == read(dir.path / "plain.jsonl"));
  const json o = json::parse(read(dir.path / "obs.json"));
  CHECK(o.at("format") == "turtlegas-observables/1");
  CHECK(o.at("windows") == 4);
  CHECK(o.at("per_window").size() == 4);
  CHECK(o.at("summary").at("kT").at("mean").get<double>() > 0.0);
  CHECK(o.at("summary").at("collision_rate").at("mean").get<double>() > 0.0);
  CHECK(o.at("speed_histogram").at("density").size() == 40);
  CHECK(o.at("density_profile").at("density").size() == 20);
  CHECK(o.at("walls").size() > 4);
  CHECK(!o.at("summary").contains("Z_virial"));  // a walled arena: no virial pressure
  CHECK(o.at("rdf").at("g").size() == 30);
  CHECK(o.at("msd").at("lag").size() == 6);  // lags 0..samples
  CHECK(o.at("vacf").at("vacf")[0].get<double>() > 0.0);
  CHECK(!o.at("species").empty());
  CHECK(o.at("summary").contains("D_msd"));
  CHECK(contains(read(dir.path / "pic.svg"), "class=\"ball-trail\""));
  SECTION("bad uses are refused with exit 2") {
    Result b = run(dir, {"run", gas, "--until", "3", "--svg-trails", "1"});
    CHECK(b.code == 2);
    CHECK(contains(b.err, "--svg-trails draws in the --svg picture"));
    b = run(dir, {"run", gas, "--until", "3", "--observe", P("o.json"), "--observe-window", "5"});
    CHECK(b.code == 2);
    CHECK(contains(b.err, "--observe-window"));
    b = run(dir, {"run", std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/wander.json", "--until", "1", "--observe", P("o.json")});
    CHECK(b.code == 2);
    CHECK(contains(b.err, "has turtles"));
    // Runs with turtles go through the runtime, whose impulses the trails and the observer do not
    // see: both are refused, naming the reason, and nothing is written.
    b = run(dir, {"run", std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/wander.json", "--until", "1", "--svg",
                  P("t.svg"), "--svg-trails", "1"});
    CHECK(b.code == 2);
    CHECK(contains(b.err, "has turtles"));
    CHECK(contains(b.err, "--svg-trails"));
    CHECK_FALSE(std::filesystem::exists(dir.path / "t.svg"));
    b = run(dir, {"run", gas, "--until", "1", "--mode", "step", "--svg", P("s.svg"), "--svg-trails", "1"});
    CHECK(b.code == 2);
    CHECK(contains(b.err, "step mode"));
  }
}

TEST_CASE("cli: --stats and --stats-json report the energy the zero-time rules took, by rule and by ball") {
  // issue 28, Accounting: worlds/tests/wedged_ball.json wedges ball b moving across a corridor
  // exactly its width; the rule takes its transverse energy, 0.5 of E = 0.53125, and says so.
  TempDir dir;
  const fs::path stats = dir.path / "stats.json";
  const Result r = run(dir, {"run", std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/tests/wedged_ball.json", "--until",
                             "5", "--stats", "--stats-json", stats.string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(contains(r.out, "energy rules 0.5 taken (wedged 0.5, crushed 0, folded 0"));
  const json st = json::parse(read(stats));
  const json& rules = st.at("energy_rules");
  CHECK(rules.at("wedged").get<double>() == Approx(0.5).epsilon(1e-12));
  CHECK(rules.at("crushed").get<double>() == 0.0);
  CHECK(rules.at("folded").get<double>() == 0.0);
  CHECK(rules.at("total").get<double>() == Approx(0.5).epsilon(1e-12));
  CHECK(rules.at("total").get<double>() ==
        Approx(st.at("energy_start").get<double>() - st.at("energy_end").get<double>()).epsilon(1e-12));
  REQUIRE(rules.at("bodies").size() == 1);
  CHECK(rules.at("bodies").at(0).at("id") == "b");
  CHECK(rules.at("bodies").at(0).at("taken").get<double>() == Approx(0.5).epsilon(1e-12));
  // A scene no rule acts on reports zeros and no bodies.
  const Result plain = run(dir, {"run", std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/tests/box_bounce.json", "--until",
                                 "5", "--stats-json", stats.string()});
  REQUIRE(plain.code == 0);
  const json z = json::parse(read(stats)).at("energy_rules");
  CHECK(z.at("total").get<double>() == 0.0);
  CHECK(z.at("bodies").empty());
}

TEST_CASE("cli: a row of discs exactly filling a box runs to its end with a bounded event log (issue 28 item 3)") {
  // worlds/tests/jammed_row.json: ten equal discs fill a box 20 wide, d0 moving. The impulse ran
  // down the row and back at one instant for ever (a 4 GiB log cap was hit in 26 s); the row is
  // jammed, so the run ends with a wedged event at t = 0 and the ledger books the energy along it.
  TempDir dir;
  for (const char* mode : {"exact", "step"}) {
    INFO(mode);
    const fs::path events = dir.path / "events.jsonl", stats = dir.path / "stats.json";
    const Result r = run(dir, {"run", std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/tests/jammed_row.json", "--until",
                               "10", "--mode", mode, "--events", events.string(), "--stats-json", stats.string()});
    INFO(r.err);
    REQUIRE(r.code == 0);
    CHECK(fs::file_size(events) < 4096);
    std::ifstream in(events);
    std::string line;
    std::size_t n = 0, wedged = 0;
    while (std::getline(in, line)) {
      const json e = json::parse(line);
      ++n;
      if (e.at("kind") == "wedged") {
        ++wedged;
        CHECK(e.at("t").get<double>() == 0.0);
      }
    }
    CHECK(n <= 11);  // nine collisions down the row, the wall, the wedged event
    CHECK(wedged == 1);
    const json st = json::parse(read(stats));
    CHECK(st.at("energy_rules").at("wedged").get<double>() == Approx(2.0).epsilon(1e-12));
    CHECK(st.at("energy_rules").at("total").get<double>() ==
          Approx(st.at("energy_start").get<double>() - st.at("energy_end").get<double>()).epsilon(1e-12));
  }
}

TEST_CASE("cli: --xyz writes an extended XYZ trajectory that reads back to the run's states") {
  // Parsed here as OVITO's and ASE's readers read extended XYZ: a count line, a comment line of
  // key=value pairs (Lattice, Properties, Time, pbc), then that many lines of the named columns.
  TempDir dir;
  auto P = [&](const char* name) { return (dir.path / name).string(); };
  const std::string gas = std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/thermal_gas.json";
  const Result r = run(dir, {"run", gas, "--until", "3", "--xyz", P("t.xyz"), "--xyz-every", "0.1", "--state-out",
                             P("end.json"), "--events", P("with.jsonl")});
  REQUIRE(r.code == 0);
  // The frames are stops that change nothing.
  REQUIRE(run(dir, {"run", gas, "--until", "3", "--events", P("without.jsonl")}).code == 0);
  CHECK(read(dir.path / "with.jsonl") == read(dir.path / "without.jsonl"));
  std::ifstream in(dir.path / "t.xyz");
  std::string line;
  std::vector<double> times;
  std::vector<std::vector<std::string>> last;
  while (std::getline(in, line)) {
    const std::size_t n = std::stoul(line);
    REQUIRE(std::getline(in, line));
    CHECK(contains(line, "Lattice=\"120 0 0 0 120 0 0 0 2\""));
    CHECK(contains(line, "pbc=\"T T F\""));
    CHECK(contains(line, "Properties=species:S:1:pos:R:3:velo:R:3:radius:R:1:mass:R:1:id:S:1"));
    const std::size_t at = line.find("Time=");
    REQUIRE(at != std::string::npos);
    times.push_back(std::stod(line.substr(at + 5)));
    last.clear();
    for (std::size_t k = 0; k < n; ++k) {
      REQUIRE(std::getline(in, line));
      std::istringstream cols(line);
      std::vector<std::string> c;
      for (std::string w; cols >> w;) c.push_back(w);
      REQUIRE(c.size() == 10);  // species, x y z, vx vy vz, radius, mass, id
      last.push_back(c);
    }
    CHECK(n == 900);
  }
  REQUIRE(times.size() == 31);  // t = 0, 0.1, ..., 3
  for (std::size_t k = 0; k < times.size(); ++k) CHECK(times[k] == Approx(0.1 * static_cast<double>(k)).margin(1e-12));
  // The last frame is the state at 3, digit for digit (shortest round-trip decimals).
  const json end = json::parse(read(dir.path / "end.json"));
  REQUIRE(end.at("balls").size() == last.size());
  for (std::size_t i = 0; i < last.size(); ++i) {
    const json& b = end.at("balls")[i];
    CHECK(last[i][9] == b.at("id").get<std::string>());
    CHECK(std::stod(last[i][1]) == b.at("pos")[0].get<double>());
    CHECK(std::stod(last[i][2]) == b.at("pos")[1].get<double>());
    CHECK(std::stod(last[i][4]) == b.at("vel")[0].get<double>());
    CHECK(last[i][0] == "A");
  }
  SECTION("--xyz needs --xyz-every, and the other way round; not with turtles") {
    Result b = run(dir, {"run", gas, "--until", "1", "--xyz", P("x.xyz")});
    CHECK(b.code == 2);
    CHECK(contains(b.err, "--xyz-every"));
    b = run(dir, {"run", gas, "--until", "1", "--xyz-every", "0.5"});
    CHECK(b.code == 2);
    b = run(dir, {"run", std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/wander.json", "--until", "1", "--xyz", P("x.xyz"),
                  "--xyz-every", "0.5"});
    CHECK(b.code == 2);
    CHECK(contains(b.err, "turtles"));
    CHECK(!std::filesystem::exists(dir.path / "x.xyz"));
  }
}
