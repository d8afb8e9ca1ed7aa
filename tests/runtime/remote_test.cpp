// SPDX-License-Identifier: MIT
// The input port (remote.hpp): remote turtles fed by an InputSource run exactly as C++ programs
// issuing the same commands, report touches before results, stand still without input, and the
// host's changes at boundaries (add_wall, make_remote) are part of the run.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "fixtures.hpp"
#include "turtlegas/turtle/remote.hpp"
#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/world_server.hpp"

using namespace turtlegas;
using namespace turtlegas::turtle;
using turtlegas::test::arena;
using turtlegas::test::body;

namespace {

TurtleProgram program(std::string controller) {
  TurtleProgram p;
  p.controller = std::move(controller);
  return p;
}

/// The "bumper" behaviour, written once as a decision on the last result so that it can drive a
/// C++ program and a remote turtle alike: forward 300; when touched, back 5 and turn right 90 (left
/// 60 when the touch was not in front); otherwise turn right 45.
struct Bumper {
  int phase = 0;  // 0: drive; 1: backed off, turn next; 2: turned, drive next
  bool front = true;
  RemoteCommand next(const std::optional<Result>& last) {
    using K = RemoteCommand::Kind;
    if (phase == 0 && last) {
      if (last->touched()) {
        front = last->touch().front();
        phase = 1;
        return {K::back, 5.0};
      }
      phase = 2;
      return {K::right, 45.0};
    }
    if (phase == 1) {
      phase = 2;
      return front ? RemoteCommand{K::right, 90.0} : RemoteCommand{K::left, 60.0};
    }
    phase = 0;
    return {K::forward, 300.0};
  }
};

Result run_on(Turtle& t, const RemoteCommand& c) {
  switch (c.kind) {
    case RemoteCommand::Kind::forward: return t.forward(c.amount);
    case RemoteCommand::Kind::back: return t.back(c.amount);
    case RemoteCommand::Kind::left: return t.left(c.amount);
    case RemoteCommand::Kind::right: return t.right(c.amount);
    default: FAIL("not a motion"); return {};
  }
}

/// An InputSource that drives each turtle with its own Bumper, answering each result as a client
/// in lockstep would (the reports come before the next next()).
class BumperSource : public InputSource {
 public:
  explicit BumperSource(std::size_t turtles) : bumpers_(turtles), last_(turtles) {}
  std::optional<RemoteCommand> next(std::uint64_t step, std::size_t turtle) override {
    calls.push_back({step, turtle});
    RemoteCommand c = bumpers_[turtle].next(last_[turtle]);
    last_[turtle].reset();
    return c;
  }
  void report(const RemoteReport& r) {
    reports.push_back(r);
    if (r.kind == RemoteReport::Kind::result) last_[r.turtle] = r.result;
  }
  std::vector<std::pair<std::uint64_t, std::size_t>> calls;
  std::vector<RemoteReport> reports;

 private:
  std::vector<Bumper> bumpers_;
  std::vector<std::optional<Result>> last_;
};

sim::WorldDef two_turtle_room() {
  sim::WorldDef d = arena();
  d.walls.push_back({"w", {250, 0}, {250, 150}});
  d.turtles.push_back(body("t1", {100, 100}, 90));
  d.turtles.push_back(body("t2", {300, 300}, 200, 70));
  return d;
}

bool same_log(const std::vector<LogEvent>& a, const std::vector<LogEvent>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (std::memcmp(&a[k].t, &b[k].t, sizeof(double)) != 0 || a[k].kind != b[k].kind || a[k].a != b[k].a ||
        a[k].b != b[k].b || a[k].sensors != b[k].sensors ||
        std::memcmp(&a[k].bearing, &b[k].bearing, sizeof(double)) != 0)
      return false;
  return true;
}

}  // namespace

TEST_CASE("remote turtles fed by an InputSource run bit for bit as C++ programs issuing the same commands",
          "[runtime][remote][determinism]") {
  // The C++ twin.
  Registry r = base_registry();
  r.add("bumper", [](Turtle& t, const Params&) {
    Bumper b;
    std::optional<Result> last;
    for (;;) last = run_on(t, b.next(last));
  });
  std::vector<LogEvent> cpp_log;
  WorldServer cpp(two_turtle_room(), {program("bumper"), program("bumper")}, r);
  cpp.set_event_log(&cpp_log);
  cpp.run_until(30.0);

  auto source = std::make_shared<BumperSource>(2);
  ServerOptions options;
  options.input = source;
  options.remote_reports = [&](const RemoteReport& rep) { source->report(rep); };
  std::vector<LogEvent> remote_log;
  WorldServer remote(two_turtle_room(), {program("remote"), program("remote")}, base_registry(), options);
  remote.set_event_log(&remote_log);
  remote.run_until(30.0);

  std::size_t touches = 0;
  for (const LogEvent& e : cpp_log) touches += e.kind == "touch";
  REQUIRE(touches >= 4);  // the comparison means something: both turtles bumped into things
  CHECK(same_log(cpp_log, remote_log));
  for (std::size_t i = 0; i < 2; ++i) {
    CHECK(remote.turtle(i).state.pos == cpp.turtle(i).state.pos);
    CHECK(remote.turtle(i).state.heading == cpp.turtle(i).state.heading);
    CHECK(remote.is_remote(i));
    CHECK(remote.controller(i) == "remote");
  }
  // Asked in world-file order within a boundary, boundaries in order, only when idle.
  for (std::size_t k = 1; k < source->calls.size(); ++k) {
    const auto& [s0, t0] = source->calls[k - 1];
    const auto& [s1, t1] = source->calls[k];
    CHECK((s1 > s0 || (s1 == s0 && t1 > t0)));
  }
}

TEST_CASE("a remote turtle hears its touch before its result, with sensors, contact time and the turtle's state",
          "[runtime][remote]") {
  sim::WorldDef d = arena();
  d.walls.push_back({"w", {202, 0}, {202, 400}});
  d.turtles.push_back(body("t1", {100, 100}, 90));  // facing the wall at x = 202
  struct Once : InputSource {
    int given = 0;
    std::optional<RemoteCommand> next(std::uint64_t, std::size_t) override {
      if (given++ > 0) return std::nullopt;
      RemoteCommand c{RemoteCommand::Kind::forward, 500.0};
      c.tag = 77;
      return c;
    }
  };
  std::vector<RemoteReport> reports;
  ServerOptions options;
  options.input = std::make_shared<Once>();
  options.remote_reports = [&](const RemoteReport& r) { reports.push_back(r); };
  WorldServer s(d, {program("remote")}, base_registry(), options);
  s.run_until(5.0);
  // Contact at x = 192 after 92 units at 50/s, t = 1.84, reported at the boundary 1.9.
  REQUIRE(reports.size() == 2);
  CHECK(reports[0].kind == RemoteReport::Kind::touch);
  CHECK(reports[0].touch.front());
  CHECK(reports[0].touch.what == "w");
  CHECK(reports[0].touch.kind == "wall");
  CHECK(reports[0].touch.t == Approx(1.84).margin(1e-12));
  CHECK(reports[0].touch.bearing == Approx(0).margin(1e-9));
  CHECK(reports[0].step == 19);
  CHECK(reports[0].t == Approx(1.9).margin(1e-12));
  CHECK(reports[1].kind == RemoteReport::Kind::result);
  CHECK(reports[1].command.tag == 77);
  CHECK(reports[1].command.kind == RemoteCommand::Kind::forward);
  REQUIRE(reports[1].result.touched());
  CHECK(reports[1].result.done() == Approx(92).margin(1e-9));
  CHECK(reports[1].result.touch().what == "w");
  CHECK(reports[1].odometer == Approx(92).margin(1e-9));
  CHECK(reports[1].heading == Approx(90).margin(1e-12));
  CHECK_FALSE(reports[1].position);  // no gps
  // Afterwards no input: the turtle stands where it stopped.
  CHECK(s.turtle(0).state.pos.x == Approx(192).margin(1e-9));
}

TEST_CASE("without input a remote turtle stands still; pen commands come several at one boundary",
          "[runtime][remote]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("t1", {100, 100}, 0));
  struct Scripted : InputSource {
    std::map<std::uint64_t, std::vector<RemoteCommand>> at;
    std::vector<std::uint64_t> asked;
    std::optional<RemoteCommand> next(std::uint64_t step, std::size_t) override {
      asked.push_back(step);
      auto it = at.find(step);
      if (it == at.end() || it->second.empty()) return std::nullopt;
      RemoteCommand c = it->second.front();
      it->second.erase(it->second.begin());
      return c;
    }
  };
  using K = RemoteCommand::Kind;
  auto source = std::make_shared<Scripted>();
  RemoteCommand pen_down{K::pen_down, 0.0};
  source->at[5] = {pen_down, {K::forward, 10.0}};  // both at boundary 5: the pen first, then the move
  source->at[20] = {{K::pen_up, 0.0}, {K::yield, 0.0}};
  std::vector<RemoteReport> reports;
  ServerOptions options;
  options.input = source;
  options.remote_reports = [&](const RemoteReport& r) { reports.push_back(r); };
  WorldServer s(d, {program("remote")}, base_registry(), options);
  s.run_until(0.45);
  CHECK(s.turtle(0).state.pos.y == 100);  // asked at boundaries 0..4, given nothing
  CHECK(source->asked == std::vector<std::uint64_t>{0, 1, 2, 3, 4});
  s.run_until(3.0);
  CHECK(s.turtle(0).state.pos.y == Approx(110));
  CHECK(s.turtle(0).pen_down == false);
  // The move of 10 at 50/s took 0.2 s: its result at boundary 7; pen_down's at 5; yield's at 21.
  REQUIRE(reports.size() == 4);
  CHECK(reports[0].command.kind == K::pen_down);
  CHECK(reports[0].step == 5);
  CHECK(reports[1].command.kind == K::forward);
  CHECK(reports[1].step == 7);
  CHECK(reports[1].result.done() == Approx(10));
  CHECK(reports[2].command.kind == K::pen_up);
  CHECK(reports[2].step == 20);
  CHECK(reports[3].command.kind == K::yield);
  CHECK(reports[3].step == 21);
  // The trail: where the pen went down, and where the move ended.
  CHECK(s.trail_size(0) == 2);
  CHECK(s.trail_since(0, 1).size() == 1);
  CHECK(s.trail_since(0, 1)[0].y == Approx(110));
  CHECK(s.trail_since(0, 5).empty());
}

TEST_CASE("at_boundary changes are part of the run: add_wall, refused walls, make_remote", "[runtime][remote]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("t1", {100, 100}, 90));  // a script drives it east
  d.turtles.push_back(body("t2", {100, 300}, 0));
  struct Edits : InputSource {
    std::vector<std::string> errors;
    void at_boundary(WorldServer& s, std::uint64_t step) override {
      if (step == 2) s.add_wall({"gate", {200, 50}, {200, 150}});
      if (step == 3) {
        try {
          s.add_wall({"gate", {10, 10}, {20, 20}});  // id taken
        } catch (const std::invalid_argument& e) {
          errors.push_back(e.what());
        }
        try {
          s.add_wall({"through-t2", {90, 315}, {110, 315}});  // through t2, at y = 315 then
        } catch (const std::invalid_argument& e) {
          errors.push_back(e.what());
        }
      }
      if (step == 10) s.make_remote(1);
    }
    std::optional<RemoteCommand> next(std::uint64_t, std::size_t) override { return std::nullopt; }
  };
  auto source = std::make_shared<Edits>();
  ServerOptions options;
  options.input = source;
  TurtleProgram drive = program("script");
  drive.params = nlohmann::json::parse(R"({"commands": [["forward", 300]]})");
  TurtleProgram circle = program("script");
  circle.params = nlohmann::json::parse(R"({"commands": [["forward", 1000]]})");
  std::vector<LogEvent> log;
  WorldServer s(d, {drive, circle}, base_registry(), options);
  s.set_event_log(&log);
  s.run_until(5.0);
  // t1 runs into the gate added at t = 0.2 and stops at x = 190.
  CHECK(s.turtle(0).state.pos.x == Approx(190).margin(1e-9));
  REQUIRE(source->errors.size() == 2);
  CHECK(source->errors[0] == "id 'gate' is taken; give the wall an id that no wall, ball or turtle has");
  CHECK(source->errors[1].find("overlap") != std::string::npos);
  // t2 was taken over at t = 1.0 after driving 50 units north, and stands there since.
  CHECK(s.is_remote(1));
  CHECK(s.turtle(1).state.pos.y == Approx(350).margin(1e-9));
  CHECK_THROWS_AS(s.make_remote(1), std::logic_error);
  std::vector<std::string> kinds;
  for (const LogEvent& e : log)
    if (e.kind == "wall-added" || e.kind == "takeover") kinds.push_back(e.kind + " " + e.a);
  CHECK(kinds == std::vector<std::string>{"wall-added gate", "takeover t2"});
}

TEST_CASE("a remote wall pen without builder is a fault of that turtle, reported", "[runtime][remote][isolation]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("t1", {100, 100}, 0));
  struct Wall : InputSource {
    std::optional<RemoteCommand> next(std::uint64_t step, std::size_t) override {
      if (step != 0) return std::nullopt;
      RemoteCommand c{RemoteCommand::Kind::pen_down, 0.0};
      c.pen = PenMode::wall;
      return c;
    }
  };
  std::vector<RemoteReport> reports;
  ServerOptions options;
  options.input = std::make_shared<Wall>();
  options.remote_reports = [&](const RemoteReport& r) { reports.push_back(r); };
  WorldServer s(d, {program("remote")}, base_registry(), options);
  s.run_until(1.0);
  REQUIRE(reports.size() == 1);
  CHECK(reports[0].kind == RemoteReport::Kind::fault);
  CHECK(reports[0].fault.find("may not lay walls") != std::string::npos);
  CHECK(s.turtle(0).finished);
}

TEST_CASE("an InputSource that throws ends run_until with its error", "[runtime][remote]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("t1", {100, 100}, 0));
  struct Timeout : InputSource {
    std::optional<RemoteCommand> next(std::uint64_t step, std::size_t) override {
      if (step == 3) throw std::runtime_error("no command from the client in 5 s");
      return std::nullopt;
    }
  };
  ServerOptions options;
  options.input = std::make_shared<Timeout>();
  WorldServer s(d, {program("remote")}, base_registry(), options);
  CHECK_THROWS_WITH(s.run_until(1.0), "no command from the client in 5 s");
  CHECK(s.step() == 3);
}

TEST_CASE("step() is the boundary last reached", "[runtime]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("t1", {100, 100}, 0));
  WorldServer s(d, {program("remote")}, base_registry());
  CHECK(s.step() == 0);
  s.run_until(0.05);
  CHECK(s.step() == 0);
  s.run_until(0.1 * 7);
  CHECK(s.step() == 7);
  CHECK(s.time() == 0.1 * 7);
}

TEST_CASE("a trail breaks where the pen was up and where a pen-down turtle was teleported", "[runtime][trail]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("t1", {100, 100}, 90));  // east: a dash, a gap, a dash
  d.turtles.push_back(body("t2", {100, 250}, 0));   // north with the pen down, then teleported
  struct Teleport : InputSource {
    void at_boundary(WorldServer& s, std::uint64_t step) override {
      if (step == 15) s.teleport_turtle("t2", {300, 200}, 0);
    }
    std::optional<RemoteCommand> next(std::uint64_t, std::size_t) override { return std::nullopt; }
  };
  ServerOptions options;
  options.input = std::make_shared<Teleport>();
  TurtleProgram dashes = program("script");
  dashes.params = nlohmann::json::parse(
      R"({"commands": [["pendown"], ["forward", 50], ["penup"], ["forward", 50], ["pendown"], ["forward", 50]]})");
  TurtleProgram jumper = program("script");
  jumper.params = nlohmann::json::parse(R"({"commands": [["pendown"], ["forward", 50], ["wait", 2], ["forward", 30]]})");
  WorldServer s(d, {dashes, jumper}, base_registry(), options);
  s.run_until(6.0);
  // The strokes: runs of points between breaks, repeated points dropped.
  auto strokes = [](const std::vector<sim::Vec2>& trail) {
    std::vector<std::vector<sim::Vec2>> out(1);
    for (const sim::Vec2 p : trail) {
      if (is_trail_break(p)) {
        if (!out.back().empty()) out.emplace_back();
        continue;
      }
      if (out.back().empty() || std::hypot(p.x - out.back().back().x, p.y - out.back().back().y) > 1e-9) out.back().push_back(p);
    }
    if (out.back().empty()) out.pop_back();
    return out;
  };
  auto near = [](sim::Vec2 p, double x, double y) { return std::abs(p.x - x) < 1e-9 && std::abs(p.y - y) < 1e-9; };
  const auto t1 = strokes(s.turtle(0).trail);
  REQUIRE(t1.size() == 2);  // not one line through the gap from x = 150 to 200
  REQUIRE(t1[0].size() == 2);
  CHECK(near(t1[0][0], 100, 100));
  CHECK(near(t1[0][1], 150, 100));
  REQUIRE(t1[1].size() == 2);
  CHECK(near(t1[1][0], 200, 100));
  CHECK(near(t1[1][1], 250, 100));
  const auto t2 = strokes(s.turtle(1).trail);
  REQUIRE(t2.size() == 2);  // not one line from where it was to where it was put
  REQUIRE(t2[0].size() == 2);
  CHECK(near(t2[0][0], 100, 250));
  CHECK(near(t2[0][1], 100, 300));
  REQUIRE(t2[1].size() == 2);
  CHECK(near(t2[1][0], 300, 200));
  CHECK(near(t2[1][1], 300, 230));
  // trail_since carries the breaks too (frames send trails by parts).
  std::size_t breaks = 0;
  for (const sim::Vec2 p : s.trail_since(1, 0)) breaks += is_trail_break(p) ? 1 : 0;
  CHECK(breaks == 1);
}
