// SPDX-License-Identifier: MIT
// Issue 17 for the commands that run many worlds, each in a child process: `turtlegas test` and
// `turtlegas sweep` show what runs on a terminal, stop runaway worlds at their limits, and at
// SIGINT or SIGTERM kill their children, say what ran and keep what is written whole. Waits are
// bounded (spawn.hpp, terminal.hpp); signals go to the spawned process only.
#include <signal.h>
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "run_cli.hpp"
#include "spawn.hpp"
#include "terminal.hpp"

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace turtlegas::test;

namespace {

const std::string worlds = std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/";
const std::string box_bounce = worlds + "tests/box_bounce.json";

/// worlds/tests/box_bounce.json made a runaway: the ball at 1e6 (some 10^4 wall hits per
/// simulated second, a few hundred per control step) and an `until` of 1e12 s.
const std::string long_expect = R"({"format": "turtlegas-world/1",
  "arena": {"width": 100, "height": 100, "boundary": "walls"},
  "balls": [{"id": "b", "pos": [50, 50], "vel": [1e6, 0], "radius": 5}],
  "expect": [{"until": 1e12}, {"count": "ball-wall", "min": 1}]})";

/// A ball at 1e150: its first control step alone never ends.
const std::string bullet = R"({"format": "turtlegas-world/1",
  "arena": {"width": 100, "height": 100, "boundary": "walls"},
  "balls": [{"id": "bullet", "pos": [50, 50], "vel": [1e150, 3e149], "radius": 1}],
  "expect": [{"until": 1}, {"count": "ball-wall", "min": 1}]})";

/// The pids of the processes working in `dir` (a test's own scratch directory: only the turtlegas
/// processes it started, and theirs, which inherit it).
std::vector<pid_t> processes_in(const fs::path& dir) {
  std::vector<pid_t> found;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::error_code link_ec;
    if (fs::read_symlink(e.path() / "cwd", link_ec) == dir) found.push_back(static_cast<pid_t>(std::stoi(name)));
  }
  return found;
}

/// How many processes are left working in `dir` after up to `seconds`; those are then killed, so
/// that a failing test leaves no orphans running. A command reaps its children before it exits, so
/// a short wait is enough; a long one would let a short orphan end by itself.
std::size_t orphans_left(const fs::path& dir, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  std::vector<pid_t> left = processes_in(dir);
  while (!left.empty() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    left = processes_in(dir);
  }
  for (pid_t p : left) ::kill(p, SIGKILL);
  return left.size();
}

bool wait_for_text(const Spawned& p, const std::string& text, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!contains(p.out(), text) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  return contains(p.out(), text);
}

std::size_t lines_of(const std::string& s) {
  std::size_t n = 0;
  for (char c : s) n += c == '\n' ? 1 : 0;
  return n;
}

}  // namespace

TEST_CASE("suite: test and sweep on a terminal show what runs, for how long, how far and its ETA") {
  // Before: `test` of a runaway world printed nothing until its --timeout, and sweep only a line
  // as each run ended.
  TempDir dir;
  const fs::path w = dir.write("long_expect.json", long_expect);
  const OnTerminal r = run_on_terminal(dir.path, {"test", box_bounce, w.string(), "--jobs", "2", "--timeout", "5"});
  INFO(r.seen);
  REQUIRE(r.ended);
  CHECK(WEXITSTATUS(r.status) == 1);
  CHECK(contains(r.seen, "1 of 2 worlds done; running: " + w.string() + " "));
  CHECK(contains(r.seen, " s, t = "));
  CHECK(contains(r.seen, " / 1e+12 s, ETA "));
  // The timeout names how far the world got.
  CHECK(contains(r.seen, "FAIL " + w.string() + ": still running after --timeout 5 s at t = "));
  CHECK(contains(r.seen, "PASS " + box_bounce));

  // Not on a file: CI logs get the results only.
  Spawned p(dir.path, {"test", w.string(), "--timeout", "3", "--tap"});
  const auto ended = p.wait_for(30);
  REQUIRE(ended.has_value());
  CHECK(ended->code == 1);
  CHECK(!contains(p.err(), "worlds done"));
  CHECK(p.out().rfind("TAP version 13\n1..1\nnot ok 1 - ", 0) == 0);

  const fs::path g = dir.write("gas.json", R"({"format": "turtlegas-world/1", "arena": {"width": 100, "height": 100,
    "boundary": "walls"}, "gas": [{"count": 50, "radius": 1, "speed": 1e9, "seed": 3}]})");
  dir.write("sweep.json", R"({"format": "turtlegas-sweep/1", "world": "gas.json", "until": 1e9, "seeds": [1]})");
  const OnTerminal s = run_on_terminal(dir.path, {"sweep", "sweep.json", "--timeout", "4"});
  INFO(s.seen);
  REQUIRE(s.ended);
  CHECK(WEXITSTATUS(s.status) == 1);
  CHECK(contains(s.seen, "0 of 1 runs done; running: run 0 ("));
}

TEST_CASE("suite: test --max-events and --max-wall-seconds stop a runaway world, which fails as a limit") {
  // Before: test had neither option (exit 2), and these worlds ran for ever without --timeout.
  TempDir dir;
  const fs::path w = dir.write("long_expect.json", long_expect);
  const fs::path b = dir.write("bullet.json", bullet);
  const fs::path junit = dir.path / "j.xml";
  Spawned p(dir.path, {"test", box_bounce, w.string(), b.string(), "--max-events", "20000", "--junit", junit.string()});
  const auto ended = p.wait_for(60);
  REQUIRE(ended.has_value());
  INFO(p.out() << p.err());
  CHECK(ended->code == 1);
  CHECK(contains(p.out(), "PASS " + box_bounce));  // well below the limit: 22 events
  // Counted by the engine: the same place every time, in both modes' worlds (many steps of few
  // events, and one step of very many).
  CHECK(contains(p.out(), "FAIL " + w.string() + ": stopped by --max-events 20000 at t = "));
  CHECK(contains(p.out(), " / 1e+12 s (20000 events)"));
  CHECK(contains(p.out(), "FAIL " + b.string() + ": stopped by --max-events 20000 at t = 0 / 1 s (20000 events)"));
  CHECK(contains(p.out(), "1 passed, 2 failed, 0 could not run"));
  const std::string x = read(junit);
  CHECK(contains(x, "failures=\"2\""));
  CHECK(contains(x, "type=\"limit\">stopped by --max-events 20000"));
  // The same world stops at the same time again: the limit is deterministic.
  const std::string first = p.out();
  const Result again = run(dir, {"test", w.string(), "--max-events", "20000"});
  CHECK(again.code == 1);
  const std::size_t at = first.find("FAIL " + w.string());
  REQUIRE(at != std::string::npos);
  CHECK(again.out == first.substr(at, first.find('\n', at) + 1 - at));

  const auto start = std::chrono::steady_clock::now();
  Spawned q(dir.path, {"test", w.string(), b.string(), "--max-wall-seconds", "1", "--jobs", "2"});
  const auto q_ended = q.wait_for(60);
  REQUIRE(q_ended.has_value());
  INFO(q.out() << q.err());
  CHECK(q_ended->code == 1);
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(20));
  CHECK(contains(q.out(), "FAIL " + w.string() + ": stopped by --max-wall-seconds 1 at t = "));
  CHECK(contains(q.out(), "FAIL " + b.string() + ": stopped by --max-wall-seconds 1 at t = 0 / 1 s ("));
}

TEST_CASE("suite: SIGINT and SIGTERM stop turtlegas test: its worlds killed, what ran reported, the JUnit whole") {
  // Before: the parent died of the signal (no summary, no report) and its children ran on, orphans
  // in process groups of their own, until their worlds ended: here never.
  for (const int sig : {SIGINT, SIGTERM}) {
    TempDir dir;
    const fs::path w = dir.write("long_expect.json", long_expect);
    const fs::path junit = dir.path / "report.xml";
    const std::string name = sig == SIGINT ? "SIGINT" : "SIGTERM";
    Spawned p(dir.path,
              {"test", box_bounce, w.string(), w.string(), box_bounce, "--jobs", "2", "--junit", junit.string()});
    // The first world passes at once; the two runaways then run.
    REQUIRE(wait_for_text(p, "PASS " + box_bounce, 60));
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    p.send(sig);
    const auto ended = p.wait_for(30);
    REQUIRE(ended.has_value());
    INFO(name << "\n" << p.out() << p.err());
    CHECK(ended->code == 128 + sig);
    CHECK(contains(p.err(), name + ": stopping the worlds that run and writing what they did"));
    CHECK(contains(p.out(), "NOT RUN " + w.string() + ": stopped by " + name + " after "));
    CHECK(contains(p.out(), "NOT RUN " + box_bounce + ": not started: the suite was stopped by " + name));
    CHECK(contains(p.out(), "1 passed, 0 failed, 0 could not run, 3 not run: stopped by " + name));
    CHECK(orphans_left(dir.path, 0.2) == 0);
    const std::string x = read(junit);
    CHECK(contains(x, "tests=\"4\" failures=\"0\" errors=\"0\" skipped=\"3\""));
    CHECK(contains(x, "<skipped message=\"stopped by " + name));
    CHECK(x.size() > 20);
    CHECK(x.substr(x.size() - 14) == "</testsuites>\n");
    for (const auto& e : fs::directory_iterator(dir.path))
      CHECK(e.path().filename().string().find(".tmp-") == std::string::npos);
  }

  // TAP: the finished worlds' lines, the rest skipped, and a bail-out.
  TempDir dir;
  const fs::path w = dir.write("long_expect.json", long_expect);
  Spawned p(dir.path, {"test", box_bounce, w.string(), "--tap"});
  REQUIRE(wait_for_text(p, "ok 1 - " + box_bounce, 60));
  p.send(SIGTERM);
  const auto ended = p.wait_for(30);
  REQUIRE(ended.has_value());
  INFO(p.out() << p.err());
  CHECK(ended->code == 143);
  CHECK(contains(p.out(), "ok 2 - " + w.string() + " # SKIP stopped by SIGTERM after "));
  CHECK(contains(p.out(), "\nBail out! stopped by SIGTERM\n"));
  CHECK(orphans_left(dir.path, 0.2) == 0);
}

TEST_CASE("suite: SIGINT stops a sweep: its runs killed, the journal whole, and the same command finishes it") {
  // Before: the sweep died of the signal and its running children went on, orphans, to the end of
  // their runs (here: a minute of simulated gas each).
  TempDir dir;
  dir.write("gas.json", R"({"format": "turtlegas-world/1", "arena": {"width": 200, "height": 200, "boundary": "walls"},
    "gas": [{"count": 200, "radius": 2, "speed": 50, "seed": 3}]})");
  dir.write("sweep.json",
            R"({"format": "turtlegas-sweep/1", "world": "gas.json", "until": 3000, "seeds": {"count": 3}})");
  const fs::path journal = dir.path / "sweep.results.jsonl.partial";
  Spawned p(dir.path, {"sweep", "sweep.json"});
  // The header (written twice: docs/sweeps.md) and the first run's line: one run done, the next
  // running.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (lines_of(read(journal)) < 3 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  REQUIRE(lines_of(read(journal)) == 3);
  p.send(SIGINT);
  const auto ended = p.wait_for(30);
  REQUIRE(ended.has_value());
  INFO(p.out() << p.err());
  CHECK(ended->code == 130);
  CHECK(orphans_left(dir.path, 0.2) == 0);
  CHECK(contains(p.out(), "stopped by SIGINT: 1 of 3 runs have results in sweep.results.jsonl.partial; run the same "
                          "command again to go on"));
  CHECK(!fs::exists(dir.path / "sweep.results.jsonl"));  // written only when whole
  const std::string kept = read(journal);
  REQUIRE(lines_of(kept) == 3);
  const std::string run0 = kept.substr(kept.find('\n', kept.find('\n') + 1) + 1);
  CHECK(json::parse(run0).at("run") == 0);

  Spawned resumed(dir.path, {"sweep", "sweep.json"});
  const auto resumed_ended = resumed.wait_for(120);
  REQUIRE(resumed_ended.has_value());
  INFO(resumed.out() << resumed.err());
  CHECK(resumed_ended->code == 0);
  CHECK(contains(resumed.err(), "resuming: 1 of 3 runs already recorded"));
  const std::string results = read(dir.path / "sweep.results.jsonl");
  CHECK(lines_of(results) == 4);
  CHECK(contains(results, run0));  // the run done before the signal, as it was
  CHECK(!fs::exists(journal));
}
