// SPDX-License-Identifier: MIT
// The expect engine (turtlegas/world/expect.hpp): each assertion kind passing and failing, with the
// failure message checked, and the load errors of bad `expect` lists.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <string>

#include <catch2/catch.hpp>

#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/world/expect.hpp"
#include "turtlegas/world/scenario.hpp"
#include "turtlegas/world/world_file.hpp"

using namespace turtlegas;
using Catch::Matchers::Contains;
using Catch::Matchers::Equals;

namespace {

const turtle::Registry& registry() {
  static const turtle::Registry r = controllers::builtin_registry();
  return r;
}

/// A ball b in a 100 x 100 box moving right at 50 (bounces at t = 0.9 + 1.8 k), and a turtle t
/// driving up at 10 from (20, 20) into the wall w at y = 60 (touch at t = 3: centre at (20, 50)).
std::string world_text(const std::string& expect) {
  return R"({"format": "turtlegas-world/1", "arena": {"width": 100, "height": 100, "boundary": "walls"},
    "walls": [{"id": "w", "from": [5, 60], "to": [40, 60]}],
    "balls": [{"id": "b", "pos": [50, 80], "vel": [50, 0], "radius": 5}],
    "turtles": [{"id": "t", "pos": [20, 20], "heading": 0, "speed": 10,
                 "params": {"commands": [["forward", 100]]}}],
    "expect": [{"until": 5}, )" + expect + "]}";
}

world::ExpectResult run(const std::string& expect, sim::Mode mode = sim::Mode::exact) {
  const world::Scene scene = world::parse_scene(world_text(expect), "t.json", registry());
  return world::run_expectations(scene, registry(), mode);
}

void passes(const std::string& expect) {
  INFO(expect);
  const auto r = run(expect);
  CHECK(r.assertions == 1);
  CHECK(r.failures.empty());
  if (!r.failures.empty()) FAIL(r.failures[0]);
}

void fails(const std::string& expect, const std::string& message) {
  INFO(expect);
  const auto r = run(expect);
  REQUIRE(r.failures.size() == 1);
  CHECK_THAT(r.failures[0], Equals("expect[1] " + message));
}

void load_error(const std::string& expect, const std::string& path, const std::string& reason) {
  INFO(expect);
  try {
    world::parse_scene(world_text(expect), "t.json", registry());
    FAIL("expected a WorldFileError");
  } catch (const world::WorldFileError& e) {
    CHECK(e.json_path == path);
    CHECK_THAT(e.reason, Contains(reason));
  }
}

}  // namespace

TEST_CASE("event and no_event") {
  passes(R"({"event": "ball-wall", "a": "b", "b": "arena-right", "before": 1})");
  passes(R"({"event": "touch", "a": "t", "b": "w", "after": 3, "before": 3.1})");
  fails(R"({"event": "ball-wall", "b": "arena-left", "before": 2})",
        "event ball-wall (b arena-left) before t = 2: none happened (the first such event is at t = 2.7 (b with arena-left))");
  fails(R"({"event": "exit"})", "event exit: none happened by t = 5");
  passes(R"({"no_event": "exit"})");
  passes(R"({"no_event": "ball-wall", "after": 0.91, "before": 2.69})");
  fails(R"({"no_event": "turtle-wall"})", "no_event turtle-wall: 1 happened, the first at t = 3 (t with w)");
}

TEST_CASE("count") {
  passes(R"({"count": "ball-wall", "min": 3, "max": 3})");
  fails(R"({"count": "ball-wall", "min": 10})", "count ball-wall = 3, wanted >= 10");
  fails(R"({"count": "ball-wall", "a": "b", "max": 2})", "count ball-wall (a b) = 3, wanted <= 2");
}

TEST_CASE("inside, near, heading, speed") {
  passes(R"({"inside": [[0, 0], [100, 100]], "who": "*"})");
  passes(R"({"inside": [[0, 0], [100, 100]], "who": ["t", "b"]})");
  fails(R"({"inside": [[0, 0], [100, 40]], "who": "t"})", "inside [[0, 0], [100, 40]]: t is at [20, 40.33333333333333] at t = 2.033333333333333");
  passes(R"({"near": [20, 50], "who": "t", "within": 1e-9})");
  passes(R"({"near": [20, 30], "who": "t", "within": 1e-9, "at": 1})");
  fails(R"({"near": [20, 60], "who": "t", "within": 1})", "near [20, 60]: t is at [20, 50] at t = 5, distance 10, wanted <= 1");
  fails(R"({"near": [0, 0], "who": "t", "within": 1, "at": 9})", "near [0, 0] t: the run ended at t = 5 before t = 9");
  passes(R"({"heading": 0, "who": "t"})");
  passes(R"({"heading": 359.9999999999, "who": "t", "within": 1e-9})");
  fails(R"({"heading": 90, "who": "t"})", "heading 90: t heads 0 degrees at t = 5, off by 90, wanted <= 1e-09");
  passes(R"({"speed": "b", "min": 50, "max": 50})");
  fails(R"({"speed": "t", "min": 1})", "speed t = 0 at t = 5, wanted >= 1");
}

TEST_CASE("energy and max_overlap") {
  passes(R"({"energy": "conserved", "tolerance": 1e-12})");
  passes(R"({"max_overlap": 1e-9})");
  const std::string gravity = R"({"format": "turtlegas-world/1", "arena": {"width": 100, "height": 100, "boundary": "walls"},
      "effects": {"gravity": [0, -10], "restitution": 0.5},
      "balls": [{"id": "b", "pos": [50, 50], "radius": 1}],
      "expect": [{"until": 5}, {"energy": "conserved", "tolerance": 1e-6}]})";
  const world::Scene scene = world::parse_scene(gravity, "g.json", registry());
  const auto r = world::run_expectations(scene, registry(), sim::Mode::exact);
  REQUIRE(r.failures.size() == 1);
  CHECK_THAT(r.failures[0], Contains("expect[1] energy conserved: 500 at t = 0,"));
  CHECK_THAT(r.failures[0], Contains("wanted <= 1e-06"));
}

TEST_CASE("settings: until and mode") {
  const world::Scene scene =
      world::parse_scene(world_text(R"({"mode": "both"}, {"no_event": "exit"})"), "t.json", registry());
  CHECK(scene.expect.present);
  CHECK(*scene.expect.until == 5.0);
  CHECK(scene.expect.modes.size() == 2);
  CHECK(scene.expect.entries.size() == 1);
  CHECK(scene.expect.entries[0].index == 2);
  CHECK(scene.expect.entries[0].kind == "no_event");
}

TEST_CASE("bad expect lists are load errors at their JSON path") {
  load_error(R"({"evnt": "touch"})", "/expect/1/evnt", "unknown assertion key \"evnt\"; did you mean \"event\"? (an expectation names one of: until, mode, event");
  load_error(R"({"cont": "touch"})", "/expect/1/cont", "unknown assertion key \"cont\"; did you mean \"count\"? (an expectation");
  load_error(R"({"count": "touch", "event": "touch"})", "/expect/1", "put each in its own entry");
  load_error(R"({"count": "touch", "min": 1, "mx": 3})", "/expect/1/mx", "unknown key \"mx\" in a \"count\" expectation; did you mean \"max\"?");
  load_error(R"({"count": "touch"})", "/expect/1", "count needs \"min\", \"max\" or both");
  load_error(R"({"event": "tuch"})", "/expect/1/event", "unknown event kind \"tuch\"; known: ball-ball");
  load_error(R"({"event": "touch", "a": "nobody"})", "/expect/1/a", "no wall, ball or turtle has id \"nobody\"");
  load_error(R"({"heading": 0, "who": "b"})", "/expect/1/who", "no turtle has id \"b\"");
  load_error(R"({"near": [0, 0], "who": "t"})", "/expect/1", "near needs \"within\"");
  load_error(R"({"inside": [[10, 0], [0, 10]]})", "/expect/1/inside", "lower-left corner first");
  load_error(R"({"until": 3})", "/expect/1", "a second {\"until\": ...}");
  load_error(R"({"mode": "fast"})", "/expect/1/mode", "mode must be \"exact\", \"step\" or \"both\"");
  load_error(R"({"energy": "conserved"})", "/expect/1", "energy needs \"tolerance\"");
  load_error(R"(3)", "/expect/1", "an expectation must be a JSON object");
  // Paths are JSON pointers (RFC 6901), as the loader's are: `/` and `~` in a key are escaped.
  load_error(R"({"count": "touch", "min": 1, "m/x~": 3})", "/expect/1/m~1x~0", "unknown key \"m/x~\" in a \"count\"");
  load_error(R"({"a/b": 1})", "/expect/1/a~1b", "unknown assertion key \"a/b\"");
}

TEST_CASE("the kinds table") {
  for (const char* key : {"event", "no_event", "count", "inside", "near", "heading", "speed", "energy", "max_overlap"}) {
    INFO(key);
    CHECK(std::any_of(world::assertion_kinds().begin(), world::assertion_kinds().end(),
                      [&](const world::AssertionKind& k) { return k.key == key; }));
  }
}

TEST_CASE("expect: a tiny dt does not store every control-step time up front (test-tiny-dt-oom)", "[expect][regression]") {
#if defined(__SANITIZE_ADDRESS__)
  WARN("skipped under AddressSanitizer, which reserves more address space than the limit below");
  return;
#endif
  // Before: run_expectations built a vector of every k dt before running (dt 1e-9 to until 100:
  // 1e11 doubles, 800 GB) and died of it. Now the boundaries are made as the run goes: a child
  // with 256 MiB of address space is still running after five seconds (and is then killed).
  const std::string text = R"({"format": "turtlegas-world/1", "dt": 1e-9, "arena": {"width": 100, "height": 100},
    "balls": [{"id": "b", "pos": [50, 50], "radius": 1}], "expect": [{"until": 100}]})";
  const world::Scene scene = world::parse_scene(text, "tiny-dt.json", registry());
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    const rlimit limit{256u << 20, 256u << 20};
    ::setrlimit(RLIMIT_AS, &limit);
    try {
      (void)world::run_expectations(scene, registry(), sim::Mode::exact);
    } catch (...) {
      ::_exit(3);  // std::bad_alloc
    }
    ::_exit(0);
  }
  int status = 0;
  pid_t ended = 0;
  for (int k = 0; k < 250 && ended == 0; ++k) {
    ::usleep(20000);
    ended = ::waitpid(pid, &status, WNOHANG);
  }
  if (ended == 0) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
  }
  INFO("the child " << (ended == 0 ? "was still running" : "ended, status " + std::to_string(status)));
  CHECK(ended == 0);
}
