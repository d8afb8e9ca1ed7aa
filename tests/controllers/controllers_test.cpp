// SPDX-License-Identifier: MIT
// Each built-in controller, run through the world server on a small world, shows its behaviour in
// numbers.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/turtle/world_server.hpp"

using namespace turtlegas;
using turtle::LogEvent;
using turtle::TurtleProgram;
using turtle::WorldServer;

namespace {

constexpr double deg = std::numbers::pi / 180.0;

const turtle::Registry& registry() {
  static const turtle::Registry r = controllers::builtin_registry();
  return r;
}

sim::WorldDef room(double w, double h, double dt = 1.0 / 30.0) {
  sim::WorldDef d;
  d.arena.width = w;
  d.arena.height = h;
  d.arena.boundary = sim::Boundary::walls;
  d.dt = dt;
  return d;
}

sim::TurtleDef body(std::string id, sim::Vec2 pos, double heading_deg, double speed = 40.0, double turn_rate_deg = 180.0) {
  sim::TurtleDef t;
  t.id = std::move(id);
  t.pos = pos;
  t.heading = heading_deg * deg;
  t.radius = 10;
  t.speed = speed;
  t.turn_rate = turn_rate_deg * deg;
  return t;
}

TurtleProgram program(std::string controller, nlohmann::json params = nlohmann::json::object()) {
  TurtleProgram p;
  p.controller = std::move(controller);
  p.params = std::move(params);
  return p;
}

double segment_distance(sim::Vec2 p, sim::Vec2 a, sim::Vec2 b) {
  const sim::Vec2 ab = b - a;
  const double t = std::clamp(sim::dot(p - a, ab) / sim::norm2(ab), 0.0, 1.0);
  return sim::norm(p - (a + t * ab));
}

/// Distance from p to the nearest wall of the world (the arena's included).
double wall_distance(const sim::World& world, sim::Vec2 p) {
  double d = std::numeric_limits<double>::infinity();
  for (const sim::WallDef& w : world.walls()) d = std::min(d, segment_distance(p, w.from, w.to));
  return d;
}

/// What a follower did, sampled at every control step once it has first touched a wall.
struct Track {
  double max_gap = 0.0;     ///< largest distance between the turtle's rim and the nearest wall
  double travelled = 0.0;   ///< path length, units
  double winding = 0.0;     ///< signed angle swept around `centre`, radians (positive: counter-clockwise)
  double min_x = 1e300, max_x = -1e300, min_y = 1e300, max_y = -1e300;
};

Track follow(WorldServer& s, std::size_t i, double until, sim::Vec2 centre) {
  Track tr;
  const double dt = s.world().dt();
  bool found = false;
  sim::Vec2 last{};
  for (double t = dt; t <= until + 1e-9; t += dt) {
    s.run_until(t);
    const auto info = s.turtle(i);
    const sim::Vec2 p = info.state.pos;
    const double gap = wall_distance(s.world(), p) - s.world().turtle_radius(i);
    if (!found) {
      found = gap < 1e-6;
      last = p;
      continue;
    }
    tr.max_gap = std::max(tr.max_gap, gap);
    tr.travelled += sim::norm(p - last);
    const sim::Vec2 a = last - centre, b = p - centre;
    tr.winding += std::atan2(sim::cross(a, b), sim::dot(a, b));
    tr.min_x = std::min(tr.min_x, p.x), tr.max_x = std::max(tr.max_x, p.x);
    tr.min_y = std::min(tr.min_y, p.y), tr.max_y = std::max(tr.max_y, p.y);
    last = p;
  }
  return tr;
}

}  // namespace

TEST_CASE("square: a lap brings the turtle back to its start, both ways round", "[controllers]") {
  for (const bool left : {false, true}) {
    INFO("left " << left);
    sim::WorldDef d = room(400, 400);
    d.turtles.push_back(body("sq", {150, 150}, 30));  // an odd heading: the sides are not axis-aligned
    WorldServer s(d, {program("square", {{"side", 100}, {"laps", 1}, {"left", left}})}, registry());
    std::vector<LogEvent> log;
    s.set_event_log(&log);
    // One lap: 4 sides of 100 at 40/s and 4 turns of 90 degrees at 180/s, 12 s in all.
    // Two sides and two quarter turns (6 s) lead to the corner across the diagonal.
    s.run_until(6.0);
    CHECK_FALSE(s.turtle(0).finished);
    CHECK(sim::norm(s.turtle(0).state.pos - sim::Vec2{150, 150}) == Approx(100 * std::sqrt(2.0)));
    s.run_until(13.0);
    const auto info = s.turtle(0);
    CHECK(info.finished);
    CHECK(info.fault.empty());
    CHECK(std::abs(info.state.pos.x - 150) <= 1e-9);
    CHECK(std::abs(info.state.pos.y - 150) <= 1e-9);
    CHECK(std::abs(std::remainder(info.state.heading - 30 * deg, 2 * std::numbers::pi)) <= 1e-9);
    CHECK(log.empty());  // nothing touched
  }
}

TEST_CASE("spiral: grows its sides and stops at its first touch", "[controllers]") {
  sim::WorldDef d = room(300, 300);
  d.turtles.push_back(body("sp", {150, 150}, 0, 150, 360));
  d.turtles[0].radius = 5;
  TurtleProgram p = program("spiral", {{"start", 12}, {"grow", 12}});
  p.pen_down = true;
  WorldServer s(d, {p}, registry());
  std::vector<LogEvent> log;
  s.set_event_log(&log);
  s.run_until(120.0);
  const auto info = s.turtle(0);
  CHECK(info.finished);
  CHECK(info.fault.empty());
  // Exactly one contact and one touch, with the arena wall, and the turtle has not moved since.
  std::vector<LogEvent> contacts, touches;
  for (const LogEvent& e : log) (e.kind == "touch" ? touches : contacts).push_back(e);
  REQUIRE(contacts.size() == 1);
  REQUIRE(touches.size() == 1);
  CHECK(contacts[0].kind == "turtle-wall");
  CHECK(contacts[0].b.starts_with("arena-"));
  CHECK(touches[0].sensors == std::vector<std::string>{"front"});
  CHECK(std::abs(wall_distance(s.world(), info.state.pos) - 5.0) <= 1e-9);
  // The trail (a point at the end of every command, turns included): the centre, then corners
  // whose sides grow by 12 each time, the last one cut short by the touch.
  std::vector<sim::Vec2> corners;
  for (const sim::Vec2 p : info.trail)
    if (corners.empty() || corners.back() != p) corners.push_back(p);
  REQUIRE(corners.size() >= 10);
  for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
    INFO("side " << k);
    CHECK(sim::norm(corners[k] - corners[k - 1]) == Approx(12.0 * static_cast<double>(k)).margin(1e-9));
  }
  const std::size_t last = corners.size() - 1;
  CHECK(sim::norm(corners[last] - corners[last - 1]) < 12.0 * static_cast<double>(last));
  CHECK(corners.back() == info.state.pos);
  const double t_touch = contacts[0].t;
  CHECK(t_touch > 10.0);
  CHECK(t_touch < 60.0);
}

TEST_CASE("wall followers keep close to the walls and go round the room, each its own way", "[controllers]") {
  // A room with a notched corner; each follower alone in it, so they do not meet.
  for (const char* hand : {"right", "left"}) {
    INFO(hand << " hand");
    sim::WorldDef d = room(400, 300);
    d.walls.push_back({"notch-h", {300, 200}, {400, 200}});
    d.walls.push_back({"notch-v", {300, 200}, {300, 300}});
    d.turtles.push_back(body("f", {150, 120}, 270));  // heads west, into the wall at x = 0
    WorldServer s(d, {program("wall_follower", {{"hand", hand}})}, registry());
    const Track tr = follow(s, 0, 300.0, {150, 120});
    INFO(hand << ": gap " << tr.max_gap << " travelled " << tr.travelled << " winding " << tr.winding);
    CHECK(s.turtle(0).fault.empty());
    // Bounded distance: the rim never further from a wall than a probe (12) plus a back-off (3)
    // and the radius (10) that a turn away from the wall can swing it out by.
    CHECK(tr.max_gap <= 25.0);
    // A substantial distance: more than a whole lap of the room's 1400-unit outline.
    CHECK(tr.travelled > 1400.0);
    CHECK(tr.max_x - tr.min_x > 300.0);
    CHECK(tr.max_y - tr.min_y > 200.0);
    // Wall on the right inside a room: counter-clockwise; on the left: clockwise. At least one lap.
    if (std::string(hand) == "right") CHECK(tr.winding > 2 * std::numbers::pi);
    else CHECK(tr.winding < -2 * std::numbers::pi);
  }
}

TEST_CASE("wall followers round an obstacle: the pillar stays on the follower's hand", "[controllers]") {
  for (const char* hand : {"right", "left"}) {
    INFO(hand << " hand");
    sim::WorldDef d = room(500, 400);
    const sim::Vec2 c{250, 200};
    d.walls.push_back({"p-bottom", {200, 160}, {300, 160}});
    d.walls.push_back({"p-right", {300, 160}, {300, 240}});
    d.walls.push_back({"p-top", {300, 240}, {200, 240}});
    d.walls.push_back({"p-left", {200, 240}, {200, 160}});
    d.turtles.push_back(body("f", {250, 110}, 0));  // heads north, into the pillar
    WorldServer s(d, {program("wall_follower", {{"hand", hand}})}, registry());
    const Track tr = follow(s, 0, 200.0, c);
    INFO(hand << ": gap " << tr.max_gap << " travelled " << tr.travelled << " winding " << tr.winding);
    CHECK(tr.max_gap <= 25.0);
    CHECK(tr.travelled > 700.0);  // more than a lap of the pillar's 360-unit outline, at a distance
    // Outside an obstacle the senses flip: wall on the right goes clockwise round it.
    if (std::string(hand) == "right") CHECK(tr.winding < -2 * std::numbers::pi);
    else CHECK(tr.winding > 2 * std::numbers::pi);
  }
}

TEST_CASE("wander: never leaves the arena, never overlaps, keeps moving", "[controllers]") {
  sim::WorldDef d = room(400, 300, 0.05);
  d.walls.push_back({"a", {100, 100}, {180, 100}});
  d.walls.push_back({"b", {250, 200}, {320, 260}});
  d.walls.push_back({"c", {200, 0}, {200, 80}});
  std::vector<TurtleProgram> programs;
  for (int k = 0; k < 5; ++k) {
    d.turtles.push_back(body(std::string("w").append(std::to_string(k)), {50.0 + 70 * k, 160}, 72.0 * k, 50));
    programs.push_back(program("wander", {{"back_off", 4}}));
  }
  WorldServer s(d, programs, registry());
  std::vector<LogEvent> log;
  s.set_event_log(&log);
  std::vector<double> travelled(5, 0.0);
  std::vector<sim::Vec2> last;
  for (std::size_t i = 0; i < 5; ++i) last.push_back(d.turtles[i].pos);
  for (int step = 1; step <= 6000; ++step) {  // 300 s
    s.run_until(step * d.dt);
    for (std::size_t i = 0; i < 5; ++i) {
      const sim::Vec2 p = s.turtle(i).state.pos;
      INFO("turtle " << i << " at t = " << s.time() << ": " << p.x << ", " << p.y);
      REQUIRE(std::isfinite(p.x));
      REQUIRE(std::isfinite(p.y));
      REQUIRE(p.x - 10 >= -1e-9);
      REQUIRE(p.x + 10 <= 400 + 1e-9);
      REQUIRE(p.y - 10 >= -1e-9);
      REQUIRE(p.y + 10 <= 300 + 1e-9);
      travelled[i] += sim::norm(p - last[i]);
      last[i] = p;
    }
    if (step % 100 == 0) REQUIRE(s.world().measure_overlap().relative <= 1e-9);
  }
  std::size_t touches = 0;
  for (const LogEvent& e : log) touches += e.kind == "touch" ? 1 : 0;
  CHECK(touches > 50);
  for (std::size_t i = 0; i < 5; ++i) {
    INFO("turtle " << i);
    CHECK(travelled[i] > 3000.0);  // of at most 50 * 300 = 15000 at full speed
    CHECK(s.turtle(i).fault.empty());
  }
}

TEST_CASE("braitenberg: wanders a convex room on its IR ring and never touches; a slimmer bound would", "[controllers]") {
  // A room with a corner cut off (still convex); the vehicle keeps its distance to every wall above
  // its radius and travels. The same vehicle with a ring too short to see a wall before it touches
  // (range 9, below its radius: every wall reads as nothing) does touch: the readings are what
  // keep it off.
  for (const double range : {60.0, 9.0}) {
    INFO("ring range " << range);
    sim::WorldDef d = room(400, 300);
    d.walls.push_back({"cut", {0, 240}, {60, 300}});
    d.turtles.push_back(body("v", {200, 150}, 30, 30, 180));
    TurtleProgram p = program("braitenberg");
    p.senses.push_back({"ir", {0, 45, 90, 135, 180, 225, 270, 315}, range});
    WorldServer s(d, {p}, registry());
    std::vector<LogEvent> log;
    s.set_event_log(&log);
    double travelled = 0.0, closest = 1e300;
    sim::Vec2 last = d.turtles[0].pos;
    for (int step = 1; step <= 30 * 300; ++step) {  // 300 s
      s.run_until(step * d.dt);
      const sim::Vec2 pos = s.turtle(0).state.pos;
      travelled += sim::norm(pos - last);
      last = pos;
      closest = std::min(closest, wall_distance(s.world(), pos) - 10.0);
    }
    std::size_t touches = 0, senses = 0;
    for (const LogEvent& e : log) {
      touches += e.kind == "touch" ? 1 : 0;
      senses += e.kind == "sense" ? 1 : 0;
    }
    CHECK(s.turtle(0).fault.empty());
    if (range == 60.0) {
      CHECK(touches == 0);
      CHECK(closest > 0.0);
      CHECK(travelled > 1500.0);  // of at most 30 * 300 = 9000
      CHECK(senses > 4500);  // about one reading a control step
    } else {
      CHECK(touches > 0);
    }
  }
}
