// SPDX-License-Identifier: MIT
// The event log (formats/event_log.hpp): one line per event, the same line for the same event
// whether the engine's events are named through a Names view or come from the world server.
#include <catch2/catch.hpp>

#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "turtlegas/formats/event_log.hpp"
#include "turtlegas/sim/events.hpp"
#include "turtlegas/turtle/log_event.hpp"

using namespace turtlegas;

namespace {

struct Names {
  std::string_view ball(std::size_t i) const { return i == 0 ? "b0" : "b\"1"; }
  std::string_view wall(std::size_t i) const { return i == 0 ? "w0" : "w1"; }
  std::string_view turtle(std::size_t i) const { return i == 0 ? "t0" : "t1"; }
};

}  // namespace

TEST_CASE("the event log names each kind's bodies, and both inputs write the same line", "[formats]") {
  const std::vector<sim::Event> events = {
      {0.5, sim::EventKind::ball_ball, 0, 1},      {1.25, sim::EventKind::ball_wall, 1, 0},
      {1.5, sim::EventKind::ball_wall_end, 0, 1},  {2.0, sim::EventKind::exit, 1, 0},
      {2.5, sim::EventKind::exit, 1, 1},           {3.0, sim::EventKind::turtle_wall, 0, 1},
      {3.5, sim::EventKind::turtle_wall_end, 1, 0}, {4.0, sim::EventKind::turtle_turtle, 0, 1},
      {0.1, sim::EventKind::turtle_ball, 1, 1},
  };
  std::ostringstream engine;
  formats::EventLogWriter(engine).write(events, Names{});
  CHECK(engine.str() ==
        "{\"t\": 0.5, \"kind\": \"ball-ball\", \"a\": \"b0\", \"b\": \"b\\\"1\"}\n"
        "{\"t\": 1.25, \"kind\": \"ball-wall\", \"a\": \"b\\\"1\", \"b\": \"w0\"}\n"
        "{\"t\": 1.5, \"kind\": \"ball-wall-end\", \"a\": \"b0\", \"b\": \"w1\"}\n"
        "{\"t\": 2, \"kind\": \"exit\", \"a\": \"b\\\"1\"}\n"
        "{\"t\": 2.5, \"kind\": \"exit\", \"a\": \"t1\"}\n"  // b == 1: a turtle left
        "{\"t\": 3, \"kind\": \"turtle-wall\", \"a\": \"t0\", \"b\": \"w1\"}\n"
        "{\"t\": 3.5, \"kind\": \"turtle-wall-end\", \"a\": \"t1\", \"b\": \"w0\"}\n"
        "{\"t\": 4, \"kind\": \"turtle-turtle\", \"a\": \"t0\", \"b\": \"t1\"}\n"
        "{\"t\": 0.1, \"kind\": \"turtle-ball\", \"a\": \"t1\", \"b\": \"b\\\"1\"}\n");
  // The world server's events, named by the same namer, give the same bytes.
  std::vector<turtle::LogEvent> logged;
  for (const sim::Event& e : events) {
    const turtle::EventIds ids = turtle::name_event(e, Names{});
    logged.push_back({e.t, std::string(sim::to_string(e.kind)), std::string(ids.a),
                      ids.b ? std::string(*ids.b) : std::string(), {}, 0.0, {}, {}, {}});
  }
  std::ostringstream server;
  formats::EventLogWriter(server).write(logged);
  CHECK(server.str() == engine.str());
}

TEST_CASE("touch, fault and view lines carry their extra fields", "[formats]") {
  const std::vector<turtle::LogEvent> logged = {
      {1.0, "touch", "t0", "w1", {"front", "left"}, 337.5, {}, {}, {}},
      {1.0, "touch", "t0", "b0", {}, 0.0, {}, {}, {}},
      {2.0, "fault", "t1", {}, {}, 0.0, "its program threw: \"x\"\n", {}, {}},
      {3.0, "view", "v1", {}, {}, 0.0, {}, {}, "\"op\": \"close\", \"by\": \"t1\""},
  };
  std::ostringstream out;
  formats::EventLogWriter(out).write(logged);
  CHECK(out.str() ==
        "{\"t\": 1, \"kind\": \"touch\", \"a\": \"t0\", \"b\": \"w1\", \"sensors\": [\"front\", \"left\"], \"bearing\": 337.5}\n"
        "{\"t\": 1, \"kind\": \"touch\", \"a\": \"t0\", \"b\": \"b0\", \"sensors\": [], \"bearing\": 0}\n"
        "{\"t\": 2, \"kind\": \"fault\", \"a\": \"t1\", \"message\": \"its program threw: \\\"x\\\"\\n\"}\n"
        "{\"t\": 3, \"kind\": \"view\", \"a\": \"v1\", \"op\": \"close\", \"by\": \"t1\"}\n");
}
