// SPDX-License-Identifier: MIT
// The memo's mirror-image turtles (worlds/mirror.json): two turtles with mirror-image programs and
// mirror-image starting poses about x = 200 behave exactly as one turtle with a real wall on x = 200.
// Trajectories are sampled at every control step through the world server; docs/physics.md,
// "Mirror-image turtles", says why this holds and to what precision.
#include <cmath>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/turtle/world_server.hpp"
#include "turtlegas/world/world_file.hpp"

using namespace turtlegas;

namespace {

constexpr double mirror_x = 200.0;
constexpr double tolerance = 1e-12;
constexpr double until = 30.0;

struct Sample {
  sim::Vec2 pos;
  double heading;  // radians
};

struct Run {
  std::vector<std::vector<Sample>> turtles;  // per turtle, per control step
  std::vector<turtle::LogEvent> log;
};

Run run(const sim::WorldDef& def, const std::vector<turtle::TurtleProgram>& programs, sim::Mode mode) {
  const turtle::Registry registry = controllers::builtin_registry();
  turtle::ServerOptions options;
  options.mode = mode;
  turtle::WorldServer server(def, programs, registry, options);
  Run r;
  r.turtles.resize(def.turtles.size());
  server.set_event_log(&r.log);
  for (std::uint64_t k = 0;; ++k) {
    const double t = static_cast<double>(k) * def.dt;
    if (t > until) break;
    server.run_until(t);
    for (std::size_t i = 0; i < def.turtles.size(); ++i) {
      const sim::TurtleState s = server.world().turtle(i);
      r.turtles[i].push_back({s.pos, s.heading});
    }
  }
  server.set_event_log(nullptr);
  return r;
}

/// The mirror image about x = mirror_x: x reflected, heading negated (Logo headings are clockwise
/// from +y).
Sample mirrored(Sample s) { return {{2.0 * mirror_x - s.pos.x, s.pos.y}, -s.heading}; }

/// Difference of two headings (radians), in [0, pi].
double angle_between(double a, double b) {
  const double d = std::remainder(a - b, 2.0 * M_PI);
  return std::abs(d);
}

/// Bearing (degrees, [0, 360)) seen in the mirror.
double mirror_bearing(double b) { return b == 0.0 ? 0.0 : 360.0 - b; }

std::string mirror_sensor(const std::string& s) {
  if (s == "left") return "right";
  if (s == "right") return "left";
  return s;
}

std::vector<turtle::LogEvent> touches_of(const std::vector<turtle::LogEvent>& log, const std::string& who) {
  std::vector<turtle::LogEvent> out;
  for (const auto& e : log)
    if (e.kind == "touch" && e.a == who) out.push_back(e);
  return out;
}

}  // namespace

TEST_CASE("mirror-image turtles behave as one turtle and a wall on the mirror line", "[mirror]") {
  const turtle::Registry registry = controllers::builtin_registry();
  const world::Scene scene = world::load_scene(TURTLEGAS_SOURCE_DIR "/worlds/mirror.json", registry);
  REQUIRE(scene.def.turtles.size() == 2);
  REQUIRE(scene.def.turtles[0].id == "left");

  // The reference: 'left' alone, with a real wall where the mirror line is.
  sim::WorldDef alone = scene.def;
  alone.turtles.resize(1);
  alone.walls.push_back({"mirror", {mirror_x, 0.0}, {mirror_x, alone.arena.height}});
  const std::vector<turtle::TurtleProgram> alone_programs = {scene.programs[0]};

  for (sim::Mode mode : {sim::Mode::exact, sim::Mode::step}) {
    INFO((mode == sim::Mode::exact ? "exact" : "step") << " mode");
    const Run pair = run(scene.def, scene.programs, mode);
    const Run wall = run(alone, alone_programs, mode);
    REQUIRE(pair.turtles[0].size() == wall.turtles[0].size());

    double worst_left = 0.0, worst_right = 0.0, worst_heading = 0.0;
    for (std::size_t k = 0; k < wall.turtles[0].size(); ++k) {
      const Sample ref = wall.turtles[0][k];
      const Sample l = pair.turtles[0][k];
      const Sample r = mirrored(pair.turtles[1][k]);
      worst_left = std::max(worst_left, std::hypot(l.pos.x - ref.pos.x, l.pos.y - ref.pos.y));
      worst_right = std::max(worst_right, std::hypot(r.pos.x - ref.pos.x, r.pos.y - ref.pos.y));
      worst_heading = std::max({worst_heading, angle_between(l.heading, ref.heading), angle_between(r.heading, ref.heading)});
    }
    INFO("largest deviation from the wall run: left " << worst_left << ", right (mirrored) " << worst_right
                                                       << ", heading " << worst_heading << " rad");
    CHECK(worst_left <= tolerance);
    CHECK(worst_right <= tolerance);
    CHECK(worst_heading <= tolerance);

    // The event logs: each of the pair's touches is the wall run's touch, at the same time, and
    // the right turtle's is the left one's mirrored (bearing reflected, left and right exchanged).
    const auto ref = touches_of(wall.log, "left");
    const auto l = touches_of(pair.log, "left");
    const auto r = touches_of(pair.log, "right");
    REQUIRE(ref.size() == 2);
    REQUIRE(l.size() == ref.size());
    REQUIRE(r.size() == ref.size());
    for (std::size_t i = 0; i < ref.size(); ++i) {
      INFO("touch " << i);
      CHECK(l[i].t == ref[i].t);
      CHECK(r[i].t == l[i].t);
      CHECK(ref[i].b == "mirror");
      CHECK(l[i].b == "right");
      CHECK(r[i].b == "left");
      CHECK(std::abs(l[i].bearing - ref[i].bearing) <= 1e-9);
      CHECK(std::abs(mirror_bearing(r[i].bearing) - l[i].bearing) <= 1e-9);
      CHECK(l[i].sensors == ref[i].sensors);
      std::vector<std::string> r_mirrored;
      for (const auto& s : r[i].sensors) r_mirrored.push_back(mirror_sensor(s));
      CHECK(r_mirrored == l[i].sensors);
    }
    // The contact itself: a turtle-turtle event where the wall run has a turtle-wall one, at times
    // agreeing to round-off.
    std::vector<double> tt, tw;
    for (const auto& e : pair.log)
      if (e.kind == "turtle-turtle") tt.push_back(e.t);
    for (const auto& e : wall.log)
      if (e.kind == "turtle-wall") tw.push_back(e.t);
    REQUIRE(tt.size() == tw.size());
    for (std::size_t i = 0; i < tt.size(); ++i) CHECK(std::abs(tt[i] - tw[i]) <= tolerance);
  }
}
