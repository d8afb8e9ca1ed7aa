// SPDX-License-Identifier: MIT
// The world server: programs as coroutines, commands, touch interrupts, isolation of faults.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>

#include "fixtures.hpp"
#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/world_server.hpp"

using namespace turtlegas;
using namespace turtlegas::turtle;
using turtlegas::test::arena;
using turtlegas::test::body;

namespace {

// Fault recovery jumps out of a signal handler across stacks, which AddressSanitizer's stack
// bookkeeping cannot follow; those two tests run in the normal builds only.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

TurtleProgram program(std::string controller, std::string params = "{}") {
  TurtleProgram p;
  p.controller = std::move(controller);
  p.params = nlohmann::json::parse(params);
  return p;
}

/// The base registry and "random_walk": forward a random distance, back off after a touch, turn
/// a random angle.
Registry with_random_walk() {
  Registry r = base_registry();
  r.add("random_walk", [](Turtle& t, const Params&) {
    for (;;) {
      auto m = t.forward(20 + 100 * t.uniform());
      if (m.touched()) t.back(5);
      t.right(360 * t.uniform() - 180);
    }
  });
  return r;
}

/// Index of the first event in which two logs differ (times compared bit for bit), or a.size().
std::size_t first_difference(const std::vector<LogEvent>& a, const std::vector<LogEvent>& b) {
  for (std::size_t k = 0; k < a.size(); ++k)
    if (k >= b.size() || std::memcmp(&a[k].t, &b[k].t, sizeof(double)) != 0 || a[k].kind != b[k].kind ||
        a[k].a != b[k].a || a[k].b != b[k].b)
      return k;
  return a.size();
}

}  // namespace

TEST_CASE("the script controller drives a turtle", "[runtime]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("t1", {100, 100}, 0));
  WorldServer s(d, {program("script", R"({"commands": [["forward", 100], ["right", 90], ["forward", 50]]})")},
                base_registry());
  s.run_until(10.0);
  const auto info = s.turtle(0);
  CHECK(info.state.pos.x == Approx(150));
  CHECK(info.state.pos.y == Approx(200));
  CHECK(info.state.heading == Approx(M_PI / 2));
  CHECK(info.finished);
  CHECK(info.fault.empty());
}

TEST_CASE("the script controller's own errors (a script no loader checked) are faults naming the command", "[runtime]") {
  // World files are checked by the loader against the same table (turtle/script.hpp); a program
  // built by hand is not, and the controller itself must say what is wrong.
  const std::pair<const char*, const char*> cases[] = {
      {R"({"commands": [["forward", 10], ["jump", 5]]})",
       "params.commands[1]: unknown command 'jump'; known: forward, back, left, right, wait, pendown, penup"},
      {R"({"commands": [["jump"]]})", "params.commands[0]: 'jump' needs one number, e.g. [\"jump\", 100]"},
      {R"({"commands": [["wait"]]})", "params.commands[0]: 'wait' needs one number, e.g. [\"wait\", 100]"},
      {R"({"commands": [["pendown", "crayon"]]})", "params.commands[0]: a pen mode is \"line\" or \"wall\", got \"crayon\""},
      {R"({"commands": [7]})", "params.commands[0] must be [command, amount], e.g. [\"forward\", 100]"},
      {R"({"commands": 7})", "params.commands must be a list of [command, amount]"},
  };
  for (const auto& [params, fault] : cases) {
    CAPTURE(params);
    sim::WorldDef d = arena();
    d.turtles.push_back(body("t1", {100, 100}, 0));
    WorldServer s(d, {program("script", params)}, base_registry());
    s.run_until(1.0);
    CHECK(s.turtle(0).finished);
    CHECK(s.turtle(0).fault == std::string("its program threw: ") + fault);
  }
  // Every command of the table runs: penup, pendown (both pen modes need no builder for "line"),
  // wait, the turns and both moves.
  sim::WorldDef d = arena();
  d.turtles.push_back(body("t1", {100, 100}, 0));
  WorldServer s(d, {program("script", R"({"commands": [["pendown"], ["forward", 20], ["back", 10], ["penup"],
                     ["pendown", "line"], ["left", 90], ["right", 180], ["wait", 0.5]]})")},
                base_registry());
  s.run_until(10.0);
  const auto info = s.turtle(0);
  CHECK(info.fault.empty());
  CHECK(info.finished);
  CHECK(info.state.pos.x == Approx(100));
  CHECK(info.state.pos.y == Approx(110));
  CHECK(info.state.heading == Approx(M_PI / 2));
  CHECK(info.pen_down);
}

TEST_CASE("a touch cuts a command short, fires the right sensor, arrives on the next step", "[runtime]") {
  sim::WorldDef d = arena();
  d.walls.push_back({"w", {202, 0}, {202, 400}});
  d.turtles.push_back(body("t1", {100, 100}, 90));  // facing the wall at x = 202
  Registry r = base_registry();
  struct Seen {
    Result moved;
    double handler_time = -1, resumed_time = -1;
    std::string order;
  };
  static Seen seen;
  seen = {};
  r.add("probe", [](Turtle& t, const Params&) {
    t.on_touch([&](const Touch& touch) {
      seen.handler_time = t.time();
      seen.order += "handler;";
      CHECK(touch.front());
    });
    seen.moved = t.forward(500);
    seen.resumed_time = t.time();
    seen.order += "resumed;";
  });
  WorldServer s(d, {program("probe")}, r);
  std::vector<LogEvent> log;
  s.set_event_log(&log);
  s.run_until(5.0);
  // Contact at x = 192, after 92 units at 50/s: t = 1.84, inside the step that ends at 1.9; the
  // interrupt is delivered at that boundary.
  REQUIRE(seen.moved.touched());
  CHECK(seen.moved.done() == Approx(92));
  CHECK(seen.moved.touch().front());
  CHECK_FALSE(seen.moved.touch().left());
  CHECK(seen.moved.touch().bearing == Approx(0).margin(1e-9));
  CHECK(seen.moved.touch().what == "w");
  CHECK(seen.moved.touch().t == Approx(1.84));
  CHECK(seen.order == "handler;resumed;");
  CHECK(seen.resumed_time > seen.moved.touch().t);
  CHECK(seen.resumed_time == Approx(1.9));  // the next boundary, never the same instant
  bool saw_touch = false;
  for (const auto& e : log)
    if (e.kind == "touch") {
      saw_touch = true;
      CHECK(e.a == "t1");
      CHECK(e.b == "w");
      CHECK(e.sensors == std::vector<std::string>{"front"});
    }
  CHECK(saw_touch);
}

TEST_CASE("a touch handler's own command does not change the answer of the command it interrupted", "[runtime]") {
  // The handler backs off (a command of its own, suspending the program inside the handler);
  // the forward it interrupted still answers with its own distance and touch.
  sim::WorldDef d = arena();
  d.walls.push_back({"w", {202, 0}, {202, 400}});
  d.turtles.push_back(body("t1", {100, 100}, 90));  // facing the wall at x = 202
  Registry r = base_registry();
  struct Seen {
    Result moved, backed;
    int handled = 0;
  };
  static Seen seen;
  seen = {};
  r.add("recoil", [](Turtle& t, const Params&) {
    t.on_touch([&](const Touch&) {
      ++seen.handled;
      seen.backed = t.back(10);
    });
    seen.moved = t.forward(500);
  });
  WorldServer s(d, {program("recoil")}, r);
  s.run_until(5.0);
  CHECK(seen.handled == 1);
  CHECK(seen.backed.done() == Approx(10));
  CHECK_FALSE(seen.backed.touched());
  REQUIRE(seen.moved.touched());
  CHECK(seen.moved.done() == Approx(92));
  CHECK(seen.moved.touch().front());
  CHECK(seen.moved.touch().what == "w");
  CHECK(s.turtle(0).state.pos.x == Approx(182));
}

TEST_CASE("sensors follow the heading: a wall touched in front is on the left after a right turn", "[runtime]") {
  sim::WorldDef d = arena();
  d.walls.push_back({"w", {50, 0}, {50, 400}});
  d.turtles.push_back(body("t1", {100, 100}, 0));  // facing +y; the wall is 50 to the left
  Registry r = base_registry();
  static std::vector<Touch> after_turn;
  static Result moved;
  r.add("sidestep", [](Turtle& t, const Params&) {
    t.left(90);             // now facing -x, towards the wall
    moved = t.forward(100);  // stops at x = 60
    t.right(90);            // facing +y again
    after_turn = t.touching();
  });
  WorldServer s(d, {program("sidestep")}, r);
  s.run_until(5.0);
  CHECK(s.turtle(0).state.pos.x == Approx(60));
  REQUIRE(moved.touched());
  CHECK(moved.touch().front());
  REQUIRE(after_turn.size() == 1);
  CHECK(after_turn[0].left());
  CHECK_FALSE(after_turn[0].front());
  CHECK(after_turn[0].bearing == Approx(270));
}

TEST_CASE("a throwing program stops its turtle only", "[runtime][isolation]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("bad", {100, 100}, 0));
  d.turtles.push_back(body("good", {300, 100}, 0));
  Registry r = base_registry();
  r.add("thrower", [](Turtle& t, const Params&) {
    t.forward(10);
    throw std::runtime_error("kaboom");
  });
  WorldServer s(d, {program("thrower"), program("script", R"({"commands": [["forward", 100]]})")}, r);
  std::vector<LogEvent> log;
  s.set_event_log(&log);
  s.run_until(5.0);
  CHECK(s.turtle(0).fault.find("kaboom") != std::string::npos);
  CHECK(s.turtle(0).state.pos.y == Approx(110));
  CHECK(s.turtle(1).state.pos.y == Approx(200));
  CHECK(s.turtle(1).fault.empty());
  bool logged = false;
  for (const auto& e : log) logged = logged || (e.kind == "fault" && e.a == "bad");
  CHECK(logged);
}

namespace {
int recurse(int n) {
  volatile char pad[512];
  pad[0] = static_cast<char>(n);
  return n == 0 ? pad[0] : recurse(n + 1) + pad[0];
}
}  // namespace

TEST_CASE("a stack overflow is a clear error for that turtle, and the world runs on", "[runtime][isolation]") {
  if (kSanitized) {
    WARN("skipped under AddressSanitizer");
    return;
  }
  sim::WorldDef d = arena();
  d.turtles.push_back(body("deep", {100, 100}, 0));
  d.turtles.push_back(body("good", {300, 100}, 0));
  Registry r = base_registry();
  r.add("deep", [](Turtle& t, const Params&) {
    t.forward(10);
    recurse(1);
  });
  WorldServer s(d, {program("deep"), program("script", R"({"commands": [["forward", 100]]})")}, r);
  s.run_until(5.0);
  CHECK(s.turtle(0).fault.find("overflowed its stack") != std::string::npos);
  CHECK(s.turtle(1).state.pos.y == Approx(200));
  s.run_until(6.0);  // still running
  CHECK(s.time() == Approx(6.0));
}

TEST_CASE("a busy-looping program ends the run with a clear error", "[runtime][isolation]") {
  if (kSanitized) {
    WARN("skipped under AddressSanitizer");
    return;
  }
  sim::WorldDef d = arena();
  d.turtles.push_back(body("spin", {100, 100}, 0));
  Registry r = base_registry();
  r.add("spin", [](Turtle& t, const Params&) {
    t.forward(10);
    volatile std::uint64_t n = 0;
    for (;;) n = n + 1;
  });
  ServerOptions o;
  o.program_budget = 0.2;
  WorldServer s(d, {program("spin")}, r, o);
  CHECK_THROWS_WITH(s.run_until(5.0), Catch::Contains("turtle 'spin'") && Catch::Contains("busy loop"));
}

TEST_CASE("a program that returns leaves its turtle parked", "[runtime]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("t", {100, 100}, 0));
  WorldServer s(d, {program("script", R"({"commands": [["forward", 20]]})")}, base_registry());
  s.run_until(3.0);
  CHECK(s.turtle(0).finished);
  CHECK(s.turtle(0).state.pos.y == Approx(120));
  CHECK_FALSE(s.turtle(0).state.busy);
}

TEST_CASE("an unknown controller names the known ones", "[runtime]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("t", {100, 100}, 0));
  CHECK_THROWS_WITH(WorldServer(d, {program("wandr")}, base_registry()),
                    Catch::Equals("turtle 't': controller 'wandr' is not registered; known: mirror, script"));
  // A close misspelling of a registered name is suggested (fewer than 3 edits), a far one not.
  Registry r = base_registry();
  r.add("wander", [](Turtle&, const Params&) {});
  CHECK(r.not_registered("wandr") == "controller 'wandr' is not registered; known: mirror, script, wander; did you mean 'wander'?");
  CHECK(r.not_registered("scirpt") == "controller 'scirpt' is not registered; known: mirror, script, wander; did you mean 'script'?");
  CHECK(r.not_registered("spiral") == "controller 'spiral' is not registered; known: mirror, script, wander");
  CHECK_THROWS_WITH(r.require("wandr", "--controllers"),
                    "--controllers: controller 'wandr' is not registered; known: mirror, script, wander; did you mean 'wander'?");
  CHECK_NOTHROW(r.require("wander"));
}

TEST_CASE("runs are deterministic", "[runtime][determinism]") {
  auto run = [] {
    sim::WorldDef d = arena();
    d.walls.push_back({"mid", {200, 50}, {200, 350}});
    const Registry r = with_random_walk();
    for (int k = 0; k < 8; ++k)
      d.turtles.push_back(body("t" + std::to_string(k), {(k < 4 ? 40.0 : 240.0) + 40 * (k % 4), 200}, 45.0 * k));
    std::vector<TurtleProgram> programs(8, program("random_walk"));
    WorldServer s(d, programs, r);
    std::vector<LogEvent> log;
    s.set_event_log(&log);
    s.run_until(30.0);
    return log;
  };
  const auto a = run(), b = run();
  REQUIRE(a.size() == b.size());
  CHECK(a.size() > 50);
  CHECK(first_difference(a, b) == a.size());
}

TEST_CASE("where a run is cut into run_until calls does not change it", "[runtime][determinism][regression]") {
  // Many turtles, so that the engine rebases its clock often, and back-offs that last exactly one
  // control step (5 units at 50 units/s, dt 0.1), so that commands end right at a boundary. Whether
  // such a command has ended when the programs run there must not depend on the calls: the CLI cuts
  // runs into chunks by wall time.
  auto run = [](double cut) {
    sim::WorldDef d = arena();
    d.arena.width = d.arena.height = 1000;
    const Registry r = with_random_walk();
    for (int k = 0; k < 400; ++k)
      d.turtles.push_back(body("t" + std::to_string(k), {25.0 + 48 * (k % 20), 25.0 + 48 * (k / 20)}, 37.0 * k));
    for (auto& t : d.turtles) t.radius = 8;
    std::vector<TurtleProgram> programs(d.turtles.size(), program("random_walk"));
    WorldServer s(d, programs, r);
    std::vector<LogEvent> log;
    s.set_event_log(&log);
    if (cut <= 0.0) {
      s.run_until(40.0);
    } else {
      for (double t = cut; t < 40.0; t += cut) s.run_until(t);
      s.run_until(40.0);
    }
    return log;
  };
  const auto whole = run(0.0);
  CHECK(whole.size() > 10000);
  for (double cut : {0.0537, 0.25, 1.0 / 3.0}) {
    INFO("cut every " << cut << " s");
    const auto cut_run = run(cut);
    REQUIRE(cut_run.size() == whole.size());
    CHECK(first_difference(whole, cut_run) == whole.size());
  }
}
