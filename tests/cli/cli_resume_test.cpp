// SPDX-License-Identifier: MIT
// Issue 32 §4: `run --resume` of a gas goes on from the engine state its checkpoint holds, without
// simulating the time before again, and ends bit-identical to the uninterrupted run: the same state
// file, and the first run's event log followed by the resumed run's is the uninterrupted log, byte
// for byte. Exact and step mode; gravity (a barometric gas), E and B fields, inelastic collisions;
// a checkpoint at the end of a run, at a --max-events stop between two events, and a periodic one.
// A world with turtles or moving walls is still replayed (no engine state in its checkpoint); an
// edited world and a damaged engine state are refused. And the stats say how a run was resumed,
// its rate counting only what it simulated. (cli_robust_test.cpp has the checkpoints' other cases.)
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "run_cli.hpp"
#include "spawn.hpp"

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace turtlegas::test;

namespace {

const std::string worlds = std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/";

/// A gas that runs for as long as it is asked to: 200 discs in a walled box.
const std::string long_gas = R"({"format": "turtlegas-world/1", "arena": {"width": 200, "height": 200, "boundary": "walls"},
  "gas": [{"count": 200, "radius": 2, "speed": 50, "seed": 3}]})";

/// Inelastic balls under gravity: the TC rule's clocks and sliding balls are part of the state.
const std::string inelastic_gas = R"({"format": "turtlegas-world/1", "arena": {"width": 200, "height": 200, "boundary": "walls"},
  "effects": {"gravity": [0, -40], "restitution": 0.8, "tc": 0.001},
  "walls": [{"id": "slope", "from": [10, 10], "to": [190, 40]}],
  "gas": [{"count": 150, "radius": 2, "speed": 40, "seed": 5}]})";

std::vector<std::string> operator+(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

struct Resumed {
  json checkpoint;
  std::string err;
};

/// Runs `world` to `until` in one go; and as `first` (a run that writes the checkpoint c.json and
/// stops before `until`) resumed from it to `until`. The final states are the same bytes, and the
/// first run's log and the resumed run's make the uninterrupted log.
Resumed check_resume(const TempDir& dir, const std::string& world, double until, const std::vector<std::string>& first,
                     const std::vector<std::string>& extra = {}, int first_code = 0) {
  const std::string u = std::to_string(until);
  const fs::path c = dir.path / "c.json";
  const Result whole = run(dir, std::vector<std::string>{"run", world, "--until", u, "--state-out",
                                                         (dir.path / "whole.json").string(), "--events",
                                                         (dir.path / "whole.jsonl").string()} + extra);
  INFO(whole.err);
  REQUIRE(whole.code == 0);
  const Result part = run(dir, std::vector<std::string>{"run", world, "--checkpoint", c.string(), "--events",
                                                        (dir.path / "first.jsonl").string()} + first + extra);
  INFO(part.err);
  REQUIRE(part.code == first_code);
  Resumed r{json::parse(read(c)), ""};
  const Result resumed = run(dir, std::vector<std::string>{"run", world, "--until", u, "--resume", c.string(), "--state-out",
                                                           (dir.path / "resumed.json").string(), "--events",
                                                           (dir.path / "resumed.jsonl").string()} + extra);
  INFO(resumed.err);
  REQUIRE(resumed.code == 0);
  r.err = resumed.err;
  CHECK(read(dir.path / "resumed.json") == read(dir.path / "whole.json"));
  const std::string head = read(dir.path / "first.jsonl"), tail = read(dir.path / "resumed.jsonl");
  CHECK(head.size() > 0);
  CHECK(tail.size() > 0);
  CHECK(head + tail == read(dir.path / "whole.jsonl"));
  return r;
}

/// A gas's checkpoint holds its engine state, written to be resumed from.
void check_state_resume(const std::string& world, double until, const std::vector<std::string>& extra = {}) {
  TempDir dir;
  const Resumed r = check_resume(dir, world, until, {"--until", std::to_string(until / 2)}, extra);
  REQUIRE(r.checkpoint.contains("engine"));
  CHECK(r.checkpoint.at("engine").at("format") == "turtlegas-engine-state/1");
  CHECK(r.checkpoint.at("engine").at("bodies").size() > 0);
  CHECK_FALSE(contains(r.err, "replaying"));
}

}  // namespace

TEST_CASE("resume: a gas goes on from its engine state, bit-identical, exact mode") {
  check_state_resume(worlds + "gas.json", 4);
}
TEST_CASE("resume: a gas goes on from its engine state, bit-identical, step mode") {
  check_state_resume(worlds + "gas.json", 4, {"--mode", "step"});
}
TEST_CASE("resume: a gas under gravity, exact and step mode") {
  check_state_resume(worlds + "gas_gravity.json", 4);
  check_state_resume(worlds + "gas_gravity.json", 4, {"--mode", "step"});
}
TEST_CASE("resume: a gas under gravity, E and B fields, exact and step mode") {
  check_state_resume(worlds + "memo_gas_fields.json", 4);
  check_state_resume(worlds + "memo_gas_fields.json", 4, {"--mode", "step"});
}
TEST_CASE("resume: charges in a magnetic bottle (E and B, walls), exact mode") {
  check_state_resume(worlds + "magnetic_bottle.json", 6);
}
TEST_CASE("resume: inelastic balls under gravity on a slope (the TC rule's clocks, a ball sliding)") {
  TempDir dir;
  const fs::path w = dir.write("w.json", inelastic_gas);
  const Resumed r = check_resume(dir, w.string(), 7.5, {"--until", "6"});
  const json& e = r.checkpoint.at("engine");
  CHECK(e.at("last_time").size() == 150);
  // At t = 6 a ball slides along a wall (docs/physics.md, "The sliding flight"): its slide is part
  // of the state (the wall it slides on, in the last column; ~0u for none).
  std::size_t sliding = 0;
  for (const json& sl : e.at("slides")) sliding += sl.at(11) != 4294967295u ? 1 : 0;
  CHECK(sliding >= 1);
}

TEST_CASE("resume: from a stop between two events (--max-events), exact and step mode") {
  for (const char* mode : {"exact", "step"}) {
    // The run stops at its 1000th event, wherever that falls (inside a step in step mode): the
    // checkpoint is at that event's time, and the resumed run serves the events left at that time.
    INFO(mode);
    TempDir dir;
    const fs::path w = dir.write("w.json", long_gas);
    const Resumed r = check_resume(dir, w.string(), 3, {"--until", "3", "--max-events", "1000"}, {"--mode", mode}, 3);
    CHECK(r.checkpoint.at("why") == "max-events");
    CHECK(r.checkpoint.at("events") == 1000);
    CHECK(r.checkpoint.contains("engine"));
  }
}

TEST_CASE("resume: from the last periodic checkpoint of a killed run; checkpoints do not change a run") {
  TempDir dir;
  auto f = [&](const char* name) { return (dir.path / name).string(); };
  const std::string w = worlds + "bench/gas_N1e4_phi0p05.json";
  const Result whole = run(dir, {"run", w, "--until", "100", "--state-out", f("whole.json"), "--events", f("whole.jsonl")});
  REQUIRE(whole.code == 0);
  // Writing checkpoints as it goes leaves the run as it was, bit for bit (saving reads the engine).
  const Result every = run(dir, {"run", w, "--until", "100", "--state-out", f("every.json"), "--events", f("every.jsonl"),
                                 "--checkpoint", f("e.json"), "--checkpoint-every", "7"});
  REQUIRE(every.code == 0);
  CHECK(read(f("every.json")) == read(f("whole.json")));
  CHECK(read(f("every.jsonl")) == read(f("whole.jsonl")));
  // A run killed (SIGKILL: no last checkpoint) after its first periodic ones.
  {
    Spawned p(dir.path, {"run", w, "--until", "100", "--checkpoint", "c.json", "--checkpoint-every", "1"});
    REQUIRE(Spawned::wait_for_file(dir.path / "c.json", 10, 60));
    p.send(SIGKILL);
    REQUIRE(p.wait_for(60).has_value());
  }
  const json c = json::parse(read(f("c.json")));
  INFO(c.at("why") << " at t = " << c.at("t"));
  CHECK(c.at("why") != "the end of the run");
  REQUIRE(c.contains("engine"));
  const Result resumed = run(dir, {"run", w, "--until", "100", "--resume", f("c.json"), "--state-out", f("resumed.json")});
  INFO(resumed.err);
  REQUIRE(resumed.code == 0);
  CHECK(read(f("resumed.json")) == read(f("whole.json")));
}

TEST_CASE("resume: worlds with turtles or moving walls are still replayed") {
  for (const char* name : {"tag.json", "piston.json"}) {
    INFO(name);
    TempDir dir;
    const Resumed r = check_resume(dir, worlds + name, 20, {"--until", "10"});
    CHECK_FALSE(r.checkpoint.contains("engine"));
  }
}

TEST_CASE("resume: an edited world and a damaged engine state are refused") {
  TempDir dir;
  const std::string c = (dir.path / "c.json").string();
  const fs::path g = dir.write("g.json", long_gas);
  REQUIRE(run(dir, {"run", g.string(), "--until", "0.5", "--checkpoint", c}).code == 0);
  const std::string good = read(c);
  dir.write("g.json", long_gas + " ");
  const Result changed = run(dir, {"run", g.string(), "--until", "1", "--resume", c});
  CHECK(changed.code == 2);
  CHECK(contains(changed.err, "is not the one the checkpoint was written for"));
  dir.write("g.json", long_gas);

  // Edited, with its own hash made to match again (FNV-1a of the compact dump, 16 hex digits).
  auto rewrite = [&](json j) {
    j.erase("fnv1a");
    std::uint64_t h = 1469598103934665603ull;
    for (unsigned char ch : j.dump()) h = (h ^ ch) * 1099511628211ull;
    char hex[20];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
    j["fnv1a"] = hex;
    dir.write("c.json", j.dump());
  };
  // A state that is not the run's: a ball moved by 1e-9.
  json j = json::parse(good);
  j["engine"]["bodies"][7][0] = j["engine"]["bodies"][7][0].get<double>() + 1e-9;
  rewrite(j);
  const Result moved = run(dir, {"run", g.string(), "--until", "1", "--resume", c});
  CHECK(moved.code == 2);
  CHECK(contains(moved.err, "the engine state does not give the state the checkpoint hashed"));

  // Links that do not hold together.
  j = json::parse(good);
  j["engine"]["bodies"][0][7] = 100000;  // next: no such body
  rewrite(j);
  const Result broken = run(dir, {"run", g.string(), "--until", "1", "--resume", c});
  CHECK(broken.code == 2);
  CHECK(contains(broken.err, "the engine state does not fit"));

  // Another build's state is not used: the run is replayed, and ends as the whole run does.
  j = json::parse(good);
  j["engine_build"] = "0.0.1 0123abc";
  rewrite(j);
  const std::string replayed = (dir.path / "replayed.json").string(), whole = (dir.path / "whole.json").string();
  const Result other = run(dir, {"run", g.string(), "--until", "1", "--resume", c, "--state-out", replayed});
  INFO(other.err);
  CHECK(other.code == 0);
  CHECK(contains(other.err, "its engine state was written by turtlegas 0.0.1 0123abc"));
  CHECK(contains(other.err, "the run is replayed to t = 0.5 s instead"));
  REQUIRE(run(dir, {"run", g.string(), "--until", "1", "--state-out", whole}).code == 0);
  CHECK(read(replayed) == read(whole));

  // Cut: its own hash no longer matches.
  dir.write("c.json", good.substr(0, good.size() / 2) + "]]}}");
  const Result cut = run(dir, {"run", g.string(), "--until", "1", "--resume", c});
  CHECK(cut.code == 2);
}

TEST_CASE("resume: the stats say how a run was resumed, and its rate counts only what it simulated") {
  // A gas resumed from its engine state simulates only what follows the checkpoint: its stats say
  // so ("resumed": {"from": "state"}), and collisions per second count the collisions after the
  // checkpoint over this process's time (before, the whole run's collisions over the resumed part's
  // time: a rate ten times too high for a resume at 90 %). A turtle world is replayed: "replay".
  // How much faster a resume is, is a benchmark (docs/performance.md, "Resuming a gas").
  TempDir dir;
  const std::string w = worlds + "bench/gas_N1e4_phi0p05.json", c = (dir.path / "c.json").string();
  REQUIRE(fs::exists(w));
  const std::string a = (dir.path / "a.json").string(), b = (dir.path / "b.json").string();
  REQUIRE(run(dir, {"run", w, "--until", "18", "--checkpoint", c, "--stats-json", a}).code == 0);
  const Result r = run(dir, {"run", w, "--until", "20", "--resume", c, "--stats-json", b, "--stats"});
  INFO(r.err);
  REQUIRE(r.code == 0);
  const json before = json::parse(read(a)), after = json::parse(read(b));
  CHECK_FALSE(before.contains("resumed"));
  REQUIRE(after.contains("resumed"));
  CHECK(after["resumed"]["from"] == "state");
  CHECK(after["resumed"]["t"] == 18.0);
  CHECK(after["resumed"]["collisions"] == before["collisions"]);
  const double simulated = after["collisions"].get<double>() - before["collisions"].get<double>();
  const double seconds = after["wall_seconds"].get<double>() - after["check_seconds"].get<double>();
  REQUIRE(seconds > 0.0);
  CHECK(after["collisions_per_second"].get<double>() == Approx(simulated / seconds).epsilon(1e-9));
  CHECK(contains(r.out, "resumed      from the engine state at t = 18 s"));

  const std::string tw = worlds + "wall_follower.json";
  REQUIRE(fs::exists(tw));
  REQUIRE(run(dir, {"run", tw, "--until", "2", "--checkpoint", c}).code == 0);
  REQUIRE(run(dir, {"run", tw, "--until", "3", "--resume", c, "--stats-json", b}).code == 0);
  CHECK(json::parse(read(b))["resumed"]["from"] == "replay");
}
