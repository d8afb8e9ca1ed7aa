// SPDX-License-Identifier: MIT
// Runs the turtlegas program as a user would and checks exit codes, messages and output files.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

/// A fresh directory for one test case, removed afterwards.
struct TempDir {
  fs::path path;
  TempDir() {
    static int counter = 0;
    path = fs::temp_directory_path() / ("turtlegas-cli-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  fs::path write(const std::string& name, const std::string& text) const {
    std::ofstream(path / name) << text;
    return path / name;
  }
};

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Result {
  int code = -1;
  std::string out, err;
};

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

Result run(const TempDir& dir, const std::vector<std::string>& args) {
  std::string cmd = quote(TURTLEGAS_BIN);
  for (const auto& a : args) cmd += " " + quote(a);
  const fs::path out = dir.path / "stdout.txt", err = dir.path / "stderr.txt";
  cmd += " >" + quote(out.string()) + " 2>" + quote(err.string()) + " </dev/null";
  const int status = std::system(cmd.c_str());
  Result r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read(out);
  r.err = read(err);
  return r;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

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
    CHECK(contains(neg.err, "--until must be"));
    const Result dt = run(dir, {"run", w.string(), "--until", "1", "--dt", "0"});
    CHECK(dt.code == 2);
    CHECK(contains(dt.err, "--dt must be"));
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
