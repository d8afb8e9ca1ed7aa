// SPDX-License-Identifier: MIT
// The engine as a whole: analytic counts, the brute-force reference, conservation, the two modes.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include "scenes.hpp"
#include "turtlegas/sim/reference.hpp"
#include "turtlegas/sim/toi.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

namespace {

// Wall hits along one axis for a ball of radius r between 0 and L starting at x0 with speed u.
long analytic_hits(double x0, double u, double L, double r, double T) {
  if (u == 0) return 0;
  const double first = u > 0 ? (L - r - x0) / u : (x0 - r) / -u;
  if (T < first) return 0;
  return 1 + static_cast<long>(std::floor((T - first) / ((L - 2 * r) / std::abs(u))));
}

std::vector<Event> run_log(const WorldDef& d, Mode mode, double T, int chunks = 1) {
  World w(d, mode);
  std::vector<Event> log;
  w.set_event_log(&log);
  for (int k = 1; k <= chunks; ++k) w.advance_to(T * k / chunks);
  return log;
}

bool same_bits(const std::vector<Event>& a, const std::vector<Event>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (std::memcmp(&a[k].t, &b[k].t, sizeof(double)) != 0 || a[k].kind != b[k].kind || a[k].a != b[k].a ||
        a[k].b != b[k].b)
      return false;
  return true;
}

void normalise(Event& e) {
  if (e.kind == EventKind::ball_ball && e.a > e.b) std::swap(e.a, e.b);
}

}  // namespace

TEST_CASE("a ball in a box bounces the analytic number of times", "[world]") {
  const double W = 100, H = 60, r = 2, T = 1000;
  const Vec2 x0{31.7, 17.3}, v{13.1, -7.9};
  WorldDef d = box(W, H);
  d.balls.push_back(ball("b", x0, v, r));
  const long expected = analytic_hits(x0.x, v.x, W, r, T) + analytic_hits(x0.y, v.y, H, r, T);
  for (Mode mode : {Mode::exact, Mode::step}) {
    World w(d, mode);
    w.advance_to(T);
    INFO("mode " << (mode == Mode::exact ? "exact" : "step"));
    CHECK(static_cast<long>(w.stats().ball_wall) == expected);
    CHECK(w.stats().ball_wall_end == 0);
    CHECK(norm(w.ball(0).vel) == Approx(norm(v)).epsilon(1e-14));
  }
  CHECK(expected > 150);
}

TEST_CASE("exact mode reproduces the brute-force reference's events", "[world][reference]") {
  auto compare = [](const WorldDef& d, double T, std::size_t min_events) {
    World w(d, Mode::exact);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.advance_to(T);
    std::vector<BallState> final;
    auto ref = reference::events(d, T, &final);
    REQUIRE(ref.size() >= min_events);
    REQUIRE(log.size() == ref.size());
    for (std::size_t k = 0; k < ref.size(); ++k) {
      normalise(log[k]);
      normalise(ref[k]);
      INFO("event " << k << " of " << ref.size());
      REQUIRE(log[k].kind == ref[k].kind);
      REQUIRE(log[k].a == ref[k].a);
      REQUIRE(log[k].b == ref[k].b);
      // Same physics, different order of floating-point operations: times agree to round-off
      // grown by the (chaotic) dynamics over a short horizon.
      REQUIRE(log[k].t == Approx(ref[k].t).margin(1e-9));
    }
    for (std::size_t i = 0; i < final.size(); ++i) {
      REQUIRE(w.ball(i).alive == final[i].alive);
      if (!final[i].alive) continue;
      REQUIRE(w.ball(i).pos.x == Approx(final[i].pos.x).margin(1e-7));
      REQUIRE(w.ball(i).pos.y == Approx(final[i].pos.y).margin(1e-7));
    }
  };
  SECTION("a gas in a box") { compare(random_gas(40, 0.2, 1.0, 5.0, 11), 6.0, 150); }
  SECTION("a gas with interior walls and wall ends") {
    WorldDef d = random_gas(30, 0.1, 1.0, 5.0, 12);
    const double s = d.arena.width;
    d.walls.push_back({"slant", {0.3 * s, 0.25 * s}, {0.55 * s, 0.6 * s}});
    d.walls.push_back({"bar", {0.7 * s, 0.52 * s}, {0.9 * s, 0.52 * s}});
    // Drop balls the new walls overlap.
    std::vector<BallDef> keep;
    for (const auto& b : d.balls) {
      bool clear = true;
      for (const auto& w : d.walls) {
        const Segment seg = make_segment(w.from, w.to);
        const double foot = std::clamp(dot(b.pos - seg.p1, seg.u), 0.0, seg.len);
        clear = clear && norm(b.pos - seg.p1 - foot * seg.u) > b.radius;
      }
      if (clear) keep.push_back(b);
    }
    d.balls = keep;
    compare(d, 4.0, 60);
  }
  SECTION("a gas under gravity") {
    WorldDef d = random_gas(30, 0.15, 1.0, 5.0, 13);
    d.effects.gravity = {0.3, -9.8};
    d.walls.push_back({"ledge", {0.2 * d.arena.width, 0.3 * d.arena.height}, {0.45 * d.arena.width, 0.35 * d.arena.height}});
    std::vector<BallDef> keep;
    const Segment seg = make_segment(d.walls[0].from, d.walls[0].to);
    for (const auto& b : d.balls) {
      const double foot = std::clamp(dot(b.pos - seg.p1, seg.u), 0.0, seg.len);
      if (norm(b.pos - seg.p1 - foot * seg.u) > b.radius) keep.push_back(b);
    }
    d.balls = keep;
    compare(d, 3.0, 100);
  }
  SECTION("an open arena: balls exit") {
    WorldDef d = random_gas(30, 0.1, 1.0, 5.0, 14, Boundary::none);
    compare(d, 8.0, 40);
  }
  SECTION("inelastic") {
    WorldDef d = random_gas(30, 0.2, 1.0, 5.0, 15);
    d.effects.restitution = 0.7;
    compare(d, 4.0, 100);
  }
}

TEST_CASE("dense gas: energy drift below 1e-10 over a million collisions, no overlap", "[world][conservation]") {
  const WorldDef d = random_gas(2000, 0.3, 0.5, 3.0, 21);
  World w(d, Mode::exact);
  const double e0 = w.energy();
  const double p0 = momentum_x(w);
  double t = 0;
  while (w.stats().collisions() < 1000000) {
    t += 1.0;
    w.advance_to(t);
    REQUIRE(w.measure_overlap().relative <= 1e-9);
  }
  INFO("collisions " << w.stats().collisions() << " at t = " << t);
  CHECK(std::abs(w.energy() - e0) / e0 <= 1e-10);
  CHECK(w.max_contact_overlap().relative <= 1e-9);
  CHECK(w.stats().exits == 0);
  (void)p0;  // walls exchange momentum with the box, so only energy is conserved here
}

TEST_CASE("periodic dense gas conserves momentum and energy", "[world][conservation]") {
  const WorldDef d = random_gas(500, 0.3, 0.5, 3.0, 22, Boundary::periodic);
  World w(d, Mode::exact);
  const double e0 = w.energy(), p0 = momentum_x(w);
  w.advance_to(20.0);
  CHECK(w.stats().ball_ball > 20000);
  CHECK(w.stats().ball_wall == 0);
  CHECK(std::abs(w.energy() - e0) / e0 <= 1e-12);
  CHECK(std::abs(momentum_x(w) - p0) <= 1e-10);
  CHECK(w.measure_overlap().relative <= 1e-9);
}

TEST_CASE("step and exact modes agree on a short horizon without fields", "[world][modes]") {
  const WorldDef d = random_gas(60, 0.15, 1.0, 4.0, 31);
  World exact(d, Mode::exact), step(d, Mode::step);
  exact.advance_to(2.0);
  step.advance_to(2.0);
  CHECK(exact.stats().collisions() == step.stats().collisions());
  CHECK(exact.stats().collisions() > 20);
  for (std::size_t i = 0; i < d.balls.size(); ++i) {
    CHECK(exact.ball(i).pos.x == Approx(step.ball(i).pos.x).margin(1e-9));
    CHECK(exact.ball(i).pos.y == Approx(step.ball(i).pos.y).margin(1e-9));
  }
}

TEST_CASE("runs are deterministic and do not depend on how time is cut into calls", "[world][determinism]") {
  WorldDef d = random_gas(200, 0.2, 1.0, 4.0, 41);
  SECTION("exact") {
    const auto a = run_log(d, Mode::exact, 10.0);
    CHECK(same_bits(a, run_log(d, Mode::exact, 10.0)));
    CHECK(same_bits(a, run_log(d, Mode::exact, 10.0, 37)));
    CHECK(a.size() > 1000);
  }
  SECTION("exact under gravity") {
    d.effects.gravity = {0, -5};
    const auto a = run_log(d, Mode::exact, 5.0);
    CHECK(same_bits(a, run_log(d, Mode::exact, 5.0, 23)));
  }
  SECTION("step mode, cut inside steps") {
    d.effects.gravity = {0, -5};
    const auto a = run_log(d, Mode::step, 5.0);
    CHECK(same_bits(a, run_log(d, Mode::step, 5.0, 71)));
    CHECK(a.size() > 500);
  }
}

TEST_CASE("a World built from a consumed WorldDef runs as one built from a const ref", "[world][determinism]") {
  WorldDef d = random_gas(300, 0.2, 1.0, 4.0, 43);
  auto check_same = [](const WorldDef& def, Mode mode, double T) {
    World kept(def, mode);
    WorldDef spent = def;
    World consumed(std::move(spent), mode);
    // The ball list is freed at once, not merely moved from later.
    CHECK(spent.balls.empty());  // NOLINT(bugprone-use-after-move): the moved-from def is what is tested
    CHECK(spent.balls.capacity() == 0);
    std::vector<Event> a, b;
    kept.set_event_log(&a);
    consumed.set_event_log(&b);
    kept.advance_to(T);
    consumed.advance_to(T);
    CHECK(a.size() > 100);
    CHECK(same_bits(a, b));
    REQUIRE(kept.ball_count() == consumed.ball_count());
    for (std::size_t i = 0; i < kept.ball_count(); ++i) {
      const BallState x = kept.ball(i), y = consumed.ball(i);
      CHECK(std::memcmp(&x.pos, &y.pos, sizeof(Vec2)) == 0);
      CHECK(std::memcmp(&x.vel, &y.vel, sizeof(Vec2)) == 0);
      CHECK(kept.mass(i) == consumed.mass(i));
      CHECK(kept.radius(i) == consumed.radius(i));
    }
  };
  SECTION("exact") { check_same(d, Mode::exact, 5.0); }
  SECTION("exact under gravity") {
    d.effects.gravity = {0, -5};
    check_same(d, Mode::exact, 5.0);
  }
  SECTION("step") { check_same(d, Mode::step, 5.0); }
  SECTION("periodic") { check_same(random_gas(300, 0.2, 1.0, 4.0, 47, Boundary::periodic), Mode::exact, 5.0); }
  SECTION("with collision layers (the engine with extras)") {
    for (auto& b : d.balls) b.layers = {2u, 0xffffffffu};
    check_same(d, Mode::exact, 5.0);
  }
  SECTION("a scene the engine refuses gives the same error") {
    d.arena.cell = 0.5;
    CHECK_THROWS_WITH(World(WorldDef(d), Mode::exact), Catch::Contains("largest ball"));
  }
}

TEST_CASE("without ball_ball, balls pass through each other", "[world][effects]") {
  WorldDef d = box(100, 100);
  d.effects.ball_ball = false;
  d.balls.push_back(ball("a", {20, 50}, {10, 0}));
  d.balls.push_back(ball("b", {80, 50}, {-10, 0}));
  World w(d, Mode::exact);
  w.advance_to(5.0);
  CHECK(w.stats().ball_ball == 0);
  CHECK(w.ball(0).pos.x == Approx(70));
  CHECK(w.ball(1).pos.x == Approx(30));
}

TEST_CASE("without ball_ball, exact mode sizes its cells by the walls, not by the number of balls", "[world][effects][grid]") {
  // Balls that meet only walls gain nothing from a fine table: each crossing is an event that
  // finds no partner. A box of side 400 has 1600 units of wall: cells of 400^2 / 1600 = 100.
  auto scene = [](int n) {
    WorldDef d = box(400, 400);
    d.effects.ball_ball = false;
    for (int k = 0; k < n; ++k) {
      const int row = k / 32, col = k % 32;
      d.balls.push_back(ball("b" + std::to_string(k), {6.0 + 12.0 * col, 6.0 + 12.0 * row}, {7, 3}));
    }
    return d;
  };
  for (int n : {10, 1000}) {
    World w(scene(n), Mode::exact);
    CHECK(w.cell_size() == Approx(100));
    CHECK(w.cells_x() == 4);
  }
  // Interior walls: 1600 of box plus 3 x 400 across it, so 400^2 / 2800.
  WorldDef d = scene(100);
  for (int k = 1; k <= 3; ++k) d.walls.push_back(WallDef{"w" + std::to_string(k), {100.0 * k, 0}, {100.0 * k, 400}});
  d.balls.clear();
  for (int k = 0; k < 100; ++k) d.balls.push_back(ball("b" + std::to_string(k), {50, 2.0 + 3.9 * k}, {7, 3}));
  CHECK(World(d, Mode::exact).cell_size() == Approx(400.0 * 400.0 / 2800.0));
  // Step mode keeps the finer table (it has no crossing events; fine cells keep walls away), and
  // so does a scene whose balls meet each other.
  CHECK(World(scene(1000), Mode::step).cell_size() < 20);
  WorldDef gas = scene(1000);
  gas.effects.ball_ball = true;
  CHECK(World(gas, Mode::exact).cell_size() < 20);
  // In 20 s each ball runs 140 along x and 60 along y: about 2 crossings of cells 100 wide, where
  // the table sized for 0.3 balls a cell (6.9 wide) gave about 29.
  World w(scene(1000), Mode::exact);
  w.advance_to(20.0);
  CHECK(w.stats().ball_wall > 200);
  CHECK(w.stats().cell_crossings > 1000);
  CHECK(w.stats().cell_crossings < 3000);
}

TEST_CASE("an open arena removes balls with an exit event at the crossing time", "[world][boundary]") {
  WorldDef d = box(100, 100, Boundary::none);
  d.balls.push_back(ball("a", {50, 50}, {10, 0}));
  for (Mode mode : {Mode::exact, Mode::step}) {
    World w(d, mode);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.advance_to(10.0);
    REQUIRE(log.size() == 1);
    CHECK(log[0].kind == EventKind::exit);
    CHECK_FALSE(w.ball(0).alive);
    if (mode == Mode::exact) CHECK(log[0].t == Approx(5.0));
    else CHECK(log[0].t == Approx(5.0).margin(d.dt));  // noticed at the next step boundary
  }
}

TEST_CASE("a periodic arena wraps balls and collides pairs across the seam", "[world][boundary]") {
  WorldDef d = box(100, 100, Boundary::periodic);
  d.balls.push_back(ball("a", {2, 50}, {-1, 0}));
  d.balls.push_back(ball("b", {95, 50}, {1, 0}));
  for (Mode mode : {Mode::exact, Mode::step}) {
    World w(d, mode);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.advance_to(4.0);
    // Across the seam they are 7 apart: contact at distance 2 after 2.5 s.
    REQUIRE(log.size() == 1);
    CHECK(log[0].kind == EventKind::ball_ball);
    CHECK(log[0].t == Approx(2.5).epsilon(1e-12));
    CHECK(w.ball(0).vel.x == Approx(1));
    CHECK(w.ball(1).vel.x == Approx(-1));
  }
}

TEST_CASE("cell sizes that break the rules are clear errors", "[world][grid]") {
  WorldDef d = box(1600, 1600);
  d.balls.push_back(ball("fast", {800, 800}, {600, 0}, 4));
  d.arena.cell = 40;
  // 600 units/s * 1/30 s = 20 per step; 2 * (4 + 20) = 48 > 40.
  CHECK_THROWS_WITH(World(d, Mode::step), Catch::Contains("arena.cell 40") && Catch::Contains("step mode"));
  CHECK_NOTHROW(World(d, Mode::exact));
  d.arena.cell = 6;
  CHECK_THROWS_WITH(World(d, Mode::exact), Catch::Contains("largest ball"));
}

TEST_CASE("step mode widens its search when a collision speeds a ball up", "[world][modes]") {
  // A light ball hit by a heavy one leaves at almost twice the heavy one's speed, past what the
  // memo's rule allowed for at the start of the step. It must still not pass through the wall.
  WorldDef d = box(200, 100);
  d.dt = 0.1;
  d.balls.push_back(ball("heavy", {20, 50}, {40, 0}, 1.0, 1000.0));
  d.balls.push_back(ball("light", {26, 50}, {0, 0}, 1.0, 1.0));
  World w(d, Mode::step);
  w.advance_to(10.0);
  CHECK(w.measure_overlap().relative <= 1e-9);
  CHECK(w.stats().exits == 0);
  for (std::size_t i = 0; i < 2; ++i) {
    CHECK(w.ball(i).pos.x >= 1.0);
    CHECK(w.ball(i).pos.x <= 199.0);
  }
}

TEST_CASE("a wall added while the world runs enters the predictions at once", "[world][walls]") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    INFO((mode == Mode::exact ? "exact" : "step"));
    WorldDef d = box(200, 100);
    d.balls.push_back(ball("b", {20, 50}, {10, 0}, 1));
    World w(d, mode);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.advance_to(1.0);  // the ball is at x = 30
    // Overlapping the ball: refused, nothing changes.
    CHECK_THROWS_WITH(w.add_wall({"bad", {30, 0}, {30, 100}}), Catch::Contains("would overlap a ball"));
    CHECK(w.walls().size() == 4);
    const std::size_t k = w.add_wall({"new", {61, 20}, {61, 80}});
    CHECK(w.walls()[k].id == "new");
    w.advance_to(5.0);
    // Contact when the centre reaches x = 60: t = 4.
    REQUIRE(log.size() == 1);
    CHECK(log[0].kind == EventKind::ball_wall);
    CHECK(log[0].b == k);
    CHECK(log[0].t == Approx(4.0).epsilon(1e-12));
    CHECK(w.ball(0).vel.x == Approx(-10));
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}
