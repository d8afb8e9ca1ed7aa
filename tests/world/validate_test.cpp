// SPDX-License-Identifier: MIT
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <catch2/catch.hpp>

#include "turtlegas/sim/world_def.hpp"

namespace sim = turtlegas::sim;
using Where = sim::DefProblem::Where;

namespace {

constexpr double not_a_number = std::numeric_limits<double>::quiet_NaN();
constexpr double inf = std::numeric_limits<double>::infinity();

sim::WorldDef scene() {
  sim::WorldDef def;
  def.arena.width = 100;
  def.arena.height = 80;
  return def;
}

sim::BallDef ball(std::string id, sim::Vec2 pos, double radius = 1.0) {
  sim::BallDef b;
  b.id = std::move(id);
  b.pos = pos;
  b.radius = radius;
  return b;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// The problem validate() finds; fails the test if there is none.
sim::DefProblem problem_of(const sim::WorldDef& def) {
  const auto p = sim::validate(def);
  REQUIRE(p.has_value());
  INFO(p->message);
  CHECK(p->message.find('\n') == std::string::npos);
  return *p;
}

}  // namespace

TEST_CASE("an empty scene and a normal one are valid") {
  CHECK_FALSE(sim::validate(sim::WorldDef{}).has_value());
  sim::WorldDef def = scene();
  def.walls.push_back({"w", {10, 10}, {90, 10}});
  def.balls.push_back(ball("a", {50, 50}, 3));
  def.balls.push_back(ball("b", {60, 50}, 3));
  CHECK_FALSE(sim::validate(def).has_value());
}

TEST_CASE("scalar fields") {
  struct Case {
    const char* name;
    void (*spoil)(sim::WorldDef&);
    Where where;
    const char* field;
    const char* text;
  };
  const Case cases[] = {
      {"dt 0", [](sim::WorldDef& d) { d.dt = 0; }, Where::world, "dt", "dt must be"},
      {"dt nan", [](sim::WorldDef& d) { d.dt = not_a_number; }, Where::world, "dt", "dt must be"},
      {"width 0", [](sim::WorldDef& d) { d.arena.width = 0; }, Where::arena, "width", "arena width must be finite and > 0 (got 0)"},
      {"height inf", [](sim::WorldDef& d) { d.arena.height = inf; }, Where::arena, "height", "(got inf)"},
      {"cell -1", [](sim::WorldDef& d) { d.arena.cell = -1.0; }, Where::arena, "cell", "leave it out"},
      {"gravity nan", [](sim::WorldDef& d) { d.effects.gravity.y = not_a_number; }, Where::effects, "gravity", "finite"},
      {"electric inf", [](sim::WorldDef& d) { d.effects.electric.x = inf; }, Where::effects, "electric", "finite"},
      {"magnetic nan", [](sim::WorldDef& d) { d.effects.magnetic = not_a_number; }, Where::effects, "magnetic", "finite"},
      {"restitution 1.5", [](sim::WorldDef& d) { d.effects.restitution = 1.5; }, Where::effects, "restitution", "[0, 1] (got 1.5)"},
      {"restitution -0.1", [](sim::WorldDef& d) { d.effects.restitution = -0.1; }, Where::effects, "restitution", "[0, 1]"},
      {"restitution nan", [](sim::WorldDef& d) { d.effects.restitution = not_a_number; }, Where::effects, "restitution", "[0, 1]"},
      {"tc 0", [](sim::WorldDef& d) { d.effects.tc = 0; }, Where::effects, "tc", "tc must be"},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    sim::WorldDef def = scene();
    c.spoil(def);
    const sim::DefProblem p = problem_of(def);
    CHECK(p.where == c.where);
    CHECK(p.field == c.field);
    CHECK(contains(p.message, c.text));
  }
  sim::WorldDef edge = scene();
  edge.effects.restitution = 0.0;
  CHECK_FALSE(sim::validate(edge).has_value());
}

TEST_CASE("walls") {
  sim::WorldDef def = scene();
  def.walls.push_back({"ok", {0, 0}, {1, 1}});
  def.walls.push_back({"dot", {5, 5}, {5, 5}});
  sim::DefProblem p = problem_of(def);
  CHECK(p.where == Where::wall);
  CHECK(p.index == 1);
  CHECK(contains(p.message, "wall 'dot' has zero length"));

  def.walls[1].to = {not_a_number, 3};
  p = problem_of(def);
  CHECK(p.index == 1);
  CHECK(p.field == "to");
  CHECK(contains(p.message, "finite"));
}

TEST_CASE("balls: numbers, radius, mass") {
  auto check = [](const sim::BallDef& b, const char* field, const char* text) {
    INFO(field);
    sim::WorldDef def = scene();
    def.balls.push_back(ball("first", {10, 10}));
    def.balls.push_back(b);
    const sim::DefProblem p = problem_of(def);
    CHECK(p.where == Where::ball);
    CHECK(p.index == 1);
    CHECK(p.field == field);
    CHECK(contains(p.message, text));
  };
  sim::BallDef b = ball("b", {50, 50});
  b.radius = 0;
  check(b, "radius", "ball 'b': radius must be > 0 (got 0)");
  b.radius = -2;
  check(b, "radius", "(got -2)");
  b = ball("b", {50, 50});
  b.mass = 0;
  check(b, "mass", "mass must be > 0 (got 0)");
  b.mass = 1;
  b.vel = {inf, 0};
  check(b, "vel", "vel must be finite");
  b.vel = {};
  b.charge = not_a_number;
  check(b, "charge", "charge must be finite");
  b = ball("b", {not_a_number, 50});
  check(b, "pos", "pos must be finite");
}

TEST_CASE("balls inside the arena") {
  sim::WorldDef def = scene();
  def.balls.push_back(ball("edge", {0, 80}, 5));  // centre on the edge: fine for boundary none
  CHECK_FALSE(sim::validate(def).has_value());
  def.balls.push_back(ball("out", {100.5, 40}, 1));
  sim::DefProblem p = problem_of(def);
  CHECK(p.index == 1);
  CHECK(p.field == "pos");
  CHECK(contains(p.message, "ball 'out' at [100.5, 40] is outside the arena [0, 100] x [0, 80]"));

  // Boundary walls: the whole disc must be inside; touching the wall is allowed.
  def = scene();
  def.arena.boundary = sim::Boundary::walls;
  def.balls.push_back(ball("touch", {5, 75}, 5));
  CHECK_FALSE(sim::validate(def).has_value());
  def.balls.push_back(ball("sticks", {50, 76}, 5));
  p = problem_of(def);
  CHECK(p.index == 1);
  CHECK(contains(p.message, "sticks out of the arena walls"));

  def = scene();
  def.arena.boundary = sim::Boundary::periodic;
  def.balls.push_back(ball("huge", {50, 40}, 40));
  p = problem_of(def);
  CHECK(p.field == "radius");
  CHECK(contains(p.message, "periodic image"));
}

TEST_CASE("ids are unique across walls, balls and arena walls") {
  sim::WorldDef def = scene();
  def.walls.push_back({"x", {0, 0}, {1, 1}});
  def.balls.push_back(ball("x", {50, 50}));
  sim::DefProblem p = problem_of(def);
  CHECK(p.where == Where::ball);
  CHECK(p.index == 0);
  CHECK(p.field == "id");
  CHECK(contains(p.message, "duplicate id 'x' (already used by wall #0)"));

  def = scene();
  def.balls.push_back(ball("arena-left", {50, 50}));
  CHECK_FALSE(sim::validate(def).has_value());
  def.arena.boundary = sim::Boundary::walls;
  p = problem_of(def);
  CHECK(contains(p.message, "arena wall"));

  // Anonymous objects (built in code) are not duplicates of each other.
  def = scene();
  def.balls.push_back(ball("", {20, 20}));
  def.balls.push_back(ball("", {40, 20}));
  def.walls.push_back({"", {0, 0}, {1, 1}});
  CHECK_FALSE(sim::validate(def).has_value());
}

TEST_CASE("ball-ball overlaps; exactly touching is allowed") {
  sim::WorldDef def = scene();
  def.balls.push_back(ball("a", {10, 10}, 2));
  def.balls.push_back(ball("b", {14, 10}, 2));      // touching along x
  def.balls.push_back(ball("c", {30, 30}, 2.5));
  def.balls.push_back(ball("d", {33, 34}, 2.5));    // touching along a 3-4-5 diagonal
  CHECK_FALSE(sim::validate(def).has_value());

  def.balls.push_back(ball("e", {13.5, 13}, 1.5));  // overlaps b only
  const sim::DefProblem p = problem_of(def);
  CHECK(p.where == Where::ball);
  CHECK(p.index == 4);
  CHECK(contains(p.message, "ball 'e' at [13.5, 13] overlaps ball 'b' at [14, 10]"));

  // Balls that do not collide with each other may overlap.
  def.effects.ball_ball = false;
  CHECK_FALSE(sim::validate(def).has_value());
}

TEST_CASE("ball-wall overlaps; touching is allowed") {
  sim::WorldDef def = scene();
  def.walls.push_back({"w", {10, 40}, {90, 40}});
  def.balls.push_back(ball("on-side", {50, 42}, 2));  // touches the side
  def.balls.push_back(ball("at-end", {95, 40}, 5));   // touches the end point
  def.balls.push_back(ball("corner", {6, 43}, 5));    // 3-4-5 from the end point
  CHECK_FALSE(sim::validate(def).has_value());

  def.balls.push_back(ball("cross", {30, 41}, 2));
  sim::DefProblem p = problem_of(def);
  CHECK(p.index == 3);
  CHECK(p.field == "pos");
  CHECK(contains(p.message, "ball 'cross' (radius 2) at [30, 41] overlaps wall 'w' from [10, 40] to [90, 40]"));

  sim::WorldDef end = scene();
  end.walls.push_back({"w", {10, 40}, {90, 40}});
  end.balls.push_back(ball("near-end", {92, 37}, 4));  // 3.6 from the end point, beyond the segment
  CHECK(contains(problem_of(end).message, "overlaps wall 'w'"));

  // Ball-wall contacts are checked even when ball-ball collisions are off.
  def.effects.ball_ball = false;
  p = problem_of(def);
  CHECK(p.index == 3);
}

TEST_CASE("long and diagonal walls are found in every cell they cross") {
  sim::WorldDef def = scene();
  def.arena.width = 1000;
  def.arena.height = 1000;
  def.walls.push_back({"diag", {-50, -20}, {1100, 1013}});
  // Many small balls so the grid is fine; none touches the wall.
  for (int i = 0; i < 100; ++i)
    for (int j = 0; j < 100; ++j) {
      const sim::Vec2 p{5.0 + 10 * i, 5.0 + 10 * j};
      const sim::Vec2 a = def.walls[0].from, b = def.walls[0].to;
      const double dist = std::abs(sim::cross(b - a, p - a)) / sim::norm(b - a);
      if (dist > 3.0) def.balls.push_back(ball("b" + std::to_string(i * 100 + j), p, 1));
    }
  CHECK_FALSE(sim::validate(def).has_value());
  // One more ball, 0.5 from the wall half way along: it overlaps the wall and nothing else.
  const sim::Vec2 a = def.walls[0].from, b = def.walls[0].to;
  const sim::Vec2 mid = a + 0.5 * (b - a);
  def.balls.push_back(ball("hit", mid + 0.5 * (sim::perp(b - a) / sim::norm(b - a)), 0.6));
  const sim::DefProblem p = problem_of(def);
  CHECK(p.index == def.balls.size() - 1);
  CHECK(contains(p.message, "overlaps wall 'diag'"));
}

TEST_CASE("periodic arenas: overlaps across the seam") {
  sim::WorldDef def = scene();
  def.arena.boundary = sim::Boundary::periodic;
  def.balls.push_back(ball("left", {1, 40}, 2));
  def.balls.push_back(ball("right", {98, 40}, 2));  // 3 apart across x = 0
  sim::DefProblem p = problem_of(def);
  CHECK(contains(p.message, "overlaps"));

  def.balls[1].pos = {97, 40};  // exactly touching across the seam
  CHECK_FALSE(sim::validate(def).has_value());

  // A corner: only the diagonal image overlaps, and only the earlier ball crosses an edge.
  def.balls[0].pos = {99, 79};
  def.balls[1].pos = {0.5, 0.5};
  def.balls[1].radius = 0.2;
  p = problem_of(def);
  CHECK(contains(p.message, "overlaps"));
  def.arena.boundary = sim::Boundary::none;
  CHECK_FALSE(sim::validate(def).has_value());
}

TEST_CASE("validate agrees with brute force on random scenes") {
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    INFO("seed " << seed);
    std::mt19937_64 rng(seed);
    auto unit = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
    sim::WorldDef def = scene();
    def.arena.boundary = seed % 3 == 0 ? sim::Boundary::periodic : sim::Boundary::none;
    const int walls = static_cast<int>(seed % 4);
    for (int w = 0; w < walls; ++w)
      def.walls.push_back({"w" + std::to_string(w), {unit() * 100, unit() * 80}, {unit() * 100, unit() * 80}});
    const int n = 20 + static_cast<int>(seed % 7) * 10;
    const double r_scale = seed % 2 == 0 ? 0.6 : 2.0;
    for (int i = 0; i < n; ++i)
      def.balls.push_back(ball("b" + std::to_string(i), {unit() * 100, unit() * 80}, r_scale * (0.2 + unit() * (i % 5 == 0 ? 4 : 1))));

    bool overlap = false;
    const double w = def.arena.width, h = def.arena.height;
    for (int i = 0; i < n && !overlap; ++i) {
      const sim::BallDef& a = def.balls[i];
      if (def.arena.boundary == sim::Boundary::periodic && (2 * a.radius >= w || 2 * a.radius >= h)) overlap = true;
      for (int j = i + 1; j < n; ++j) {
        sim::Vec2 d = a.pos - def.balls[j].pos;
        if (def.arena.boundary == sim::Boundary::periodic) {
          d.x -= w * std::round(d.x / w);
          d.y -= h * std::round(d.y / h);
        }
        const double s = a.radius + def.balls[j].radius;
        if (sim::norm2(d) < s * s) overlap = true;
      }
      for (const auto& wall : def.walls) {
        for (int sx = -1; sx <= 1; ++sx)
          for (int sy = -1; sy <= 1; ++sy) {
            if (def.arena.boundary != sim::Boundary::periodic && (sx != 0 || sy != 0)) continue;
            const sim::Vec2 p = a.pos + sim::Vec2{sx * w, sy * h};
            const sim::Vec2 ab = wall.to - wall.from;
            const double t = std::clamp(sim::dot(p - wall.from, ab) / sim::norm2(ab), 0.0, 1.0);
            if (sim::norm2(p - (wall.from + t * ab)) < a.radius * a.radius) overlap = true;
          }
      }
    }
    const auto p = sim::validate(def);
    if (p) INFO(p->message);
    CHECK(p.has_value() == overlap);
    if (def.arena.boundary != sim::Boundary::periodic) {
      // The same discs in a 1e9 arena: checked in their own hashed cells, not a grid over it.
      def.arena.width = def.arena.height = 1e9;
      const auto q = sim::validate(def);
      CHECK(q.has_value() == overlap);
      if (p && q) CHECK(q->message == p->message);
    }
  }
}

TEST_CASE("clustered discs in a huge arena are checked by their own cells, and an overlap is still found") {
  // Issue 29: 1e5 discs clustered in a 1e9 arena shared one cell of a grid laid over the arena, and
  // the overlap check took 4 minutes (O(N^2)). Two clusters of 50,000 discs (a bounding box of the
  // discs would be the arena again) on lattices whose neighbours touch exactly; at O(N^2) this
  // test takes minutes, at the discs' own cells well under a second.
  sim::WorldDef def = scene();
  def.arena.width = 1e9;
  def.arena.height = 1e9;
  const int side = 224;  // 224^2 = 50,176 discs per cluster
  for (const sim::Vec2 corner : {sim::Vec2{20000, 20000}, sim::Vec2{6e8, 7e8}})
    for (int i = 0; i < side * side; ++i)
      def.balls.push_back(ball("b" + std::to_string(def.balls.size()), corner + sim::Vec2{2.0 * (i % side), 2.0 * (i / side)}));
  // One large disc at a level of its own, touching a cluster's corner disc, and a small one inside
  // the large one's reach but clear of it.
  def.balls.push_back(ball("big", {20000 - 1 - 5000, 20000}, 5000));
  def.balls.push_back(ball("small", {20000 - 5000, 20000 + 5001.5}, 0.5));
  const std::size_t n = def.balls.size();
  CHECK_FALSE(sim::validate(def).has_value());

  // A disc planted in the second cluster, overlapping two neighbours: named with the first of them.
  def.balls.push_back(ball("planted", sim::Vec2{6e8, 7e8} + sim::Vec2{2.0 * 100 + 1.0, 2.0 * 50}, 0.75));
  sim::DefProblem p = problem_of(def);
  CHECK(p.index == n);
  const std::size_t first = static_cast<std::size_t>(side * side + 50 * side + 100);
  CHECK(contains(p.message, "ball 'planted' at [600000201, 700000100] overlaps ball 'b" + std::to_string(first) + "'"));
  def.balls.pop_back();

  // The large disc grown by a hair overlaps the cluster's corner disc (and its neighbour above):
  // seen from the corner disc's side (the lower level of the grid), named by the later of the two.
  def.balls[n - 2].radius = 5000.25;
  p = problem_of(def);
  CHECK(p.index == n - 2);
  CHECK(contains(p.message, "ball 'big' at [14999, 20000] overlaps ball 'b0' at [20000, 20000]"));
}

TEST_CASE("arena_walls: order, ends and ids") {
  sim::ArenaDef arena;
  arena.width = 30;
  arena.height = 20;
  const auto walls = sim::arena_walls(arena);
  REQUIRE(walls.size() == 4);
  CHECK(walls[0].id == "arena-bottom");
  CHECK(walls[0].from == sim::Vec2{0, 0});
  CHECK(walls[0].to == sim::Vec2{30, 0});
  CHECK(walls[1].id == "arena-right");
  CHECK(walls[1].from == sim::Vec2{30, 0});
  CHECK(walls[1].to == sim::Vec2{30, 20});
  CHECK(walls[2].id == "arena-top");
  CHECK(walls[2].from == sim::Vec2{30, 20});
  CHECK(walls[2].to == sim::Vec2{0, 20});
  CHECK(walls[3].id == "arena-left");
  CHECK(walls[3].from == sim::Vec2{0, 20});
  CHECK(walls[3].to == sim::Vec2{0, 0});
}

TEST_CASE("turtles: fields, placement, ids and overlaps") {
  auto turtle = [](std::string id, sim::Vec2 pos, double radius = 5.0) {
    sim::TurtleDef t;
    t.id = std::move(id);
    t.pos = pos;
    t.radius = radius;
    return t;
  };
  sim::WorldDef def = scene();
  def.turtles.push_back(turtle("t1", {20, 20}));
  def.turtles.push_back(turtle("t2", {30, 20}));  // touching t1
  CHECK_FALSE(sim::validate(def).has_value());

  struct Case {
    const char* field;
    void (*spoil)(sim::TurtleDef&);
    const char* text;
  };
  const Case cases[] = {
      {"radius", [](sim::TurtleDef& t) { t.radius = 0; }, "turtle 't2': radius must be > 0 (got 0)"},
      {"speed", [](sim::TurtleDef& t) { t.speed = -1; }, "speed must be > 0"},
      {"turn_rate", [](sim::TurtleDef& t) { t.turn_rate = not_a_number; }, "turn_rate must be > 0"},
      {"bounce", [](sim::TurtleDef& t) { t.bounce = 1.5; }, "bounce must be negative"},
      {"heading", [](sim::TurtleDef& t) { t.heading = inf; }, "heading must be finite"},
      {"pos", [](sim::TurtleDef& t) { t.pos = {200, 20}; }, "turtle 't2' at [200, 20] is outside the arena"},
  };
  for (const Case& c : cases) {
    INFO(c.field);
    sim::WorldDef bad = def;
    c.spoil(bad.turtles[1]);
    const sim::DefProblem p = problem_of(bad);
    CHECK(p.where == Where::turtle);
    CHECK(p.index == 1);
    CHECK(p.field == c.field);
    CHECK(contains(p.message, c.text));
  }

  // Turtles collide with balls even when balls pass through each other.
  sim::WorldDef mixed = def;
  mixed.effects.ball_ball = false;
  mixed.balls.push_back(ball("b", {20, 27}, 3));
  mixed.balls.push_back(ball("b-overlapping", {21, 28}, 1));  // overlaps b only: fine
  sim::DefProblem p = problem_of(mixed);
  CHECK(p.where == Where::turtle);
  CHECK(p.index == 0);
  CHECK(contains(p.message, "turtle 't1' at [20, 20] overlaps ball 'b' at [20, 27]"));

  sim::WorldDef walled = def;
  walled.walls.push_back({"w", {0, 24}, {100, 24}});
  p = problem_of(walled);
  CHECK(p.where == Where::turtle);
  CHECK(contains(p.message, "overlaps wall 'w'"));

  sim::WorldDef dup = def;
  dup.balls.push_back(ball("t2", {60, 60}));
  p = problem_of(dup);
  CHECK(p.where == Where::turtle);
  CHECK(p.index == 1);
  CHECK(contains(p.message, "duplicate id 't2' (already used by ball #0)"));
}
