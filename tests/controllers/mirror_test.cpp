// SPDX-License-Identifier: MIT
// The memo's mirror-image turtles (worlds/mirror.json): two turtles with mirror-image programs and
// mirror-image starting poses about x = 200 behave exactly as one turtle with a real wall on x = 200.
// Trajectories are sampled at every control step through the world server; docs/physics.md,
// "Mirror-image turtles", says why this holds and to what precision.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

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

// The `mirror` controller (worlds/mirror_wander.json): a random wanderer and its declared mirror
// image, which draws the wanderer's random stream. Sampled at every control step and at every
// event of both runs (the pair, and the wanderer alone beside a real wall on the mirror line).
namespace {

/// Every control step and every event time of `logs`, sorted, up to `end`.
std::vector<double> sample_times(double dt, double end, const std::vector<const std::vector<turtle::LogEvent>*>& logs) {
  std::vector<double> t;
  for (std::uint64_t k = 0; static_cast<double>(k) * dt <= end; ++k) t.push_back(static_cast<double>(k) * dt);
  for (const auto* log : logs)
    for (const auto& e : *log) t.push_back(e.t);
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end()), t.end());
  return t;
}

Run run_at(const sim::WorldDef& def, const std::vector<turtle::TurtleProgram>& programs, sim::Mode mode,
           const std::vector<double>& times, bool keep_log) {
  const turtle::Registry registry = controllers::builtin_registry();
  turtle::ServerOptions options;
  options.mode = mode;
  turtle::WorldServer server(def, programs, registry, options);
  Run r;
  r.turtles.resize(def.turtles.size());
  if (keep_log) server.set_event_log(&r.log);
  for (double t : times) {
    server.run_until(t);
    for (std::size_t i = 0; i < def.turtles.size(); ++i) {
      const sim::TurtleState s = server.world().turtle(i);
      r.turtles[i].push_back({s.pos, s.heading});
    }
  }
  server.set_event_log(nullptr);
  return r;
}

}  // namespace

TEST_CASE("a declared mirror of a random wanderer is its exact mirror image, and the mirror acts as a wall",
          "[mirror]") {
  constexpr double wander_until = 60.0;
  // 1e-12 of the arena's size (400) for positions, of the run's length for contact times: the
  // mirror is exact in the physics, and only round-off of coordinates in different binades (ulp
  // 2.8e-14 near 200) separates the runs; a wanderer's shallow contacts amplify it by 1/sin of the
  // angle of incidence (docs/physics.md, "Mirror-image turtles"). Measured over these 60 s: 2.4e-12
  // in exact mode, 7.0e-11 in step mode. Headings are turned by exactly negated angles: 1e-12 rad.
  const double pos_tolerance = 1e-12 * 400.0;
  const double time_tolerance = 1e-12 * wander_until;
  const turtle::Registry registry = controllers::builtin_registry();
  const world::Scene scene = world::load_scene(TURTLEGAS_SOURCE_DIR "/worlds/mirror_wander.json", registry);
  REQUIRE(scene.def.turtles.size() == 2);
  REQUIRE(scene.programs[1].controller == "mirror");
  sim::WorldDef alone = scene.def;
  alone.turtles.resize(1);
  alone.walls.push_back({"mirror", {mirror_x, 0.0}, {mirror_x, alone.arena.height}});
  const std::vector<turtle::TurtleProgram> alone_programs = {scene.programs[0]};

  for (sim::Mode mode : {sim::Mode::exact, sim::Mode::step}) {
    INFO((mode == sim::Mode::exact ? "exact" : "step") << " mode");
    // First the logs, for the event times; then both runs sampled at all of them.
    const std::vector<double> steps = sample_times(scene.def.dt, wander_until, {});
    const Run pair_log = run_at(scene.def, scene.programs, mode, steps, true);
    const Run wall_log = run_at(alone, alone_programs, mode, steps, true);
    const std::vector<double> times = sample_times(scene.def.dt, wander_until, {&pair_log.log, &wall_log.log});
    const Run pair = run_at(scene.def, scene.programs, mode, times, false);
    const Run wall = run_at(alone, alone_programs, mode, times, false);

    double worst_pair = 0.0, worst_wall = 0.0, worst_heading = 0.0;
    for (std::size_t k = 0; k < times.size(); ++k) {
      const Sample l = pair.turtles[0][k];
      const Sample r = mirrored(pair.turtles[1][k]);
      const Sample ref = wall.turtles[0][k];
      worst_pair = std::max(worst_pair, std::hypot(l.pos.x - r.pos.x, l.pos.y - r.pos.y));
      worst_wall = std::max({worst_wall, std::hypot(l.pos.x - ref.pos.x, l.pos.y - ref.pos.y),
                             std::hypot(r.pos.x - ref.pos.x, r.pos.y - ref.pos.y)});
      worst_heading = std::max({worst_heading, angle_between(l.heading, r.heading), angle_between(l.heading, ref.heading)});
    }
    INFO(times.size() << " samples; largest deviations: mirror pair " << worst_pair << ", from the wall run "
                      << worst_wall << ", heading " << worst_heading << " rad");
    CHECK(worst_pair <= pos_tolerance);
    CHECK(worst_wall <= pos_tolerance);
    CHECK(worst_heading <= tolerance);

    // They meet on the mirror line, when and as the wanderer alone meets the wall: each
    // turtle-turtle contact is a turtle-wall contact of the wall run at the same time, and each
    // touch of 'right' is the mirror of the touch of 'left' at that time.
    std::vector<double> tt, tw;
    for (const auto& e : pair_log.log)
      if (e.kind == "turtle-turtle") tt.push_back(e.t);
    for (const auto& e : wall_log.log)
      if (e.kind == "turtle-wall" && e.b == "mirror") tw.push_back(e.t);
    CHECK(tt.size() >= 2);  // the demonstration needs them to meet
    REQUIRE(tt.size() == tw.size());
    for (std::size_t i = 0; i < tt.size(); ++i) CHECK(std::abs(tt[i] - tw[i]) <= time_tolerance);
    const auto l = touches_of(pair_log.log, "left");
    const auto r = touches_of(pair_log.log, "right");
    const auto ref = touches_of(wall_log.log, "left");
    REQUIRE(l.size() == ref.size());
    REQUIRE(r.size() == l.size());
    for (std::size_t i = 0; i < l.size(); ++i) {
      INFO("touch " << i << " at t = " << l[i].t << " of " << l[i].b);
      CHECK(std::abs(r[i].t - l[i].t) <= time_tolerance);
      CHECK(std::abs(mirror_bearing(r[i].bearing) - l[i].bearing) <= 1e-9);
      std::vector<std::string> r_mirrored;
      for (const auto& s : r[i].sensors) r_mirrored.push_back(mirror_sensor(s));
      CHECK(r_mirrored == l[i].sensors);
      CHECK(l[i].sensors == ref[i].sensors);
      CHECK((l[i].b == "right") == (ref[i].b == "mirror"));
    }
    // Where they touch: on the line, each a radius from it.
    for (double t : tt) {
      const auto k = static_cast<std::size_t>(std::lower_bound(times.begin(), times.end(), t) - times.begin());
      REQUIRE(k < times.size());
      const double radius = scene.def.turtles[0].radius;
      CHECK(std::abs(pair.turtles[0][k].pos.x - (mirror_x - radius)) <= 1e-9);
      CHECK(std::abs(pair.turtles[1][k].pos.x - (mirror_x + radius)) <= 1e-9);
    }
  }
}

TEST_CASE("the mirror controller's params are checked, naming the turtle and the fix", "[mirror]") {
  const turtle::Registry registry = controllers::builtin_registry();
  sim::WorldDef def;
  def.arena.width = def.arena.height = 100;
  def.turtles.push_back({});
  def.turtles[0].id = "m";
  def.turtles[0].pos = {50, 50};
  turtle::TurtleProgram program;
  program.controller = "mirror";
  const std::vector<std::pair<nlohmann::json, std::string>> cases = {
      {nlohmann::json::object(), "turtle 'm': params.of: name the controller to mirror"},
      {{{"of", "wandr"}}, "turtle 'm': params.of: controller 'wandr' is not registered"},
      {{{"of", "wander"}, {"axes", 0}}, "turtle 'm': params.axes: unknown"},
      {{{"of", "wander"}, {"twin", "nobody"}}, "turtle 'm': params.twin: the id of the turtle this one mirrors"},
      {{{"of", "wander"}, {"through", {1}}}, "turtle 'm': params.through: a point of the mirror line"},
      {{{"of", "mirror"}, {"params", {{"of", "nope"}}}}, "params.of: controller 'nope' is not registered"},
  };
  for (const auto& [params, message] : cases) {
    program.params = params;
    INFO(params.dump());
    try {
      turtle::WorldServer server(def, {program}, registry, {});
      FAIL("no error");
    } catch (const std::invalid_argument& e) {
      CHECK_THAT(e.what(), Catch::Matchers::Contains(message));
    }
  }
  // A mirror of a mirror across the same line is the controller itself.
  const nlohmann::json commands = nlohmann::json::array({nlohmann::json::array({"forward", 1})});
  program.params = {{"of", "mirror"}, {"params", {{"of", "script"}, {"params", {{"commands", commands}}}}}};
  CHECK_NOTHROW(turtle::WorldServer(def, {program}, registry, {}));
}
