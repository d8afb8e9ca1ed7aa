// SPDX-License-Identifier: MIT
// learn/src/ring_cast.hpp: every ray's answer is sim::World::cast_ray's, bit for bit (distance,
// target and index), on random scenes of walls (some sharing ends), moving balls, turtles and
// collision layers, from turtles and from free points; and the caster declines the scenes it does
// not cover.
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "ring_cast.hpp"
#include "turtlegas/sim/world.hpp"

namespace sim = turtlegas::sim;
using turtlegas::learn::detail::RingCaster;

namespace {

struct Rng {
  std::mt19937_64 g;
  explicit Rng(std::uint64_t s) : g(s) {}
  double uniform(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(g() >> 11) * 0x1.0p-53; }
  int pick(int n) { return static_cast<int>(g() % static_cast<std::uint64_t>(n)); }
};

sim::Layers random_layers(Rng& rng) {
  const std::uint32_t masks[] = {0xffffffffu, 1u, 2u, 3u};
  return {rng.pick(3) == 0 ? 2u : 1u, masks[rng.pick(4)]};
}

/// A 10 x 10 lattice of 30-unit cells, each empty, a ball, a turtle or one or two walls along its
/// lower and left sides (sharing the corner): discs stay within 13 of the cell's centre, walls 14 away.
sim::WorldDef random_scene(std::uint64_t seed) {
  Rng rng(seed);
  sim::WorldDef def;
  def.arena = {300, 300, {}, sim::Boundary::walls};
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const sim::Vec2 c{15.0 + 30 * i + rng.uniform(-3, 3), 15.0 + 30 * j + rng.uniform(-3, 3)};
      const double x0 = 30.0 * i, y0 = 30.0 * j;
      switch (rng.pick(5)) {
        case 0: {
          sim::BallDef b;
          b.id = "b" + std::to_string(def.balls.size());
          b.pos = c;
          b.vel = {rng.uniform(-20, 20), rng.uniform(-20, 20)};
          b.radius = rng.uniform(2, 6);
          b.layers = random_layers(rng);
          def.balls.push_back(b);
          break;
        }
        case 1: {
          sim::TurtleDef t;
          t.id = "t" + std::to_string(def.turtles.size());
          t.pos = c;
          t.heading = rng.uniform(0, 6.283185307179586);
          t.radius = rng.uniform(5, 10);
          t.layers = random_layers(rng);
          def.turtles.push_back(t);
          break;
        }
        case 2: {
          const sim::Layers l = random_layers(rng);
          def.walls.push_back({"w" + std::to_string(def.walls.size()), {x0 + 1, y0 + 1}, {x0 + 29, y0 + 1}, l});
          if (rng.pick(2)) def.walls.push_back({"w" + std::to_string(def.walls.size()), {x0 + 1, y0 + 1}, {x0 + 1, y0 + 29}, random_layers(rng)});
          break;
        }
        default: break;
      }
    }
  return def;
}

void check_same(const sim::World& w, RingCaster& caster, sim::Vec2 o, const sim::Layers& layers, std::uint32_t self, Rng& rng) {
  std::vector<sim::Vec2> dirs;
  std::vector<double> ranges;
  double reach = 0.0;
  for (int k = 0; k < 24; ++k) {
    const double a = rng.uniform(0, 6.283185307179586);
    // Some rays exactly along the axes, where walls' lines and ends are met edge on.
    dirs.push_back(k < 4 ? sim::Vec2{k == 0 ? 1.0 : k == 1 ? -1.0 : 0.0, k == 2 ? 1.0 : k == 3 ? -1.0 : 0.0} : sim::Vec2{std::sin(a), std::cos(a)});
    ranges.push_back(rng.uniform(5, 90));
    reach = std::max(reach, ranges.back());
  }
  std::vector<sim::RayHit> got;
  caster.cast(w, o, layers, self, dirs, ranges, reach, got);
  for (std::size_t k = 0; k < dirs.size(); ++k) {
    sim::Ray ray;
    ray.origin = o;
    ray.dir = dirs[k];
    ray.range = ranges[k];
    ray.layers = layers;
    ray.self = self;
    const sim::RayHit want = w.cast_ray(ray);
    INFO("origin (" << o.x << ", " << o.y << ") ray " << k << " dir (" << dirs[k].x << ", " << dirs[k].y << ") range " << ranges[k]);
    CHECK(got[k].distance == want.distance);
    CHECK(got[k].target == want.target);
    CHECK(got[k].index == want.index);
  }
}

}  // namespace

TEST_CASE("RingCaster: cast_ray's answers on random scenes, bit for bit") {
  int hits = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    const sim::WorldDef def = random_scene(seed);
    sim::World w(def, seed % 2 ? sim::Mode::exact : sim::Mode::step);
    w.advance_to(0.55);  // the balls moved: their positions are the engine's lazy ones
    RingCaster caster(w, def);
    caster.begin(w);
    Rng rng(seed * 7919);
    for (std::uint32_t k = 0; k < def.turtles.size(); ++k) check_same(w, caster, w.turtle(k).pos, def.turtles[k].layers, k, rng);
    for (int p = 0; p < 40; ++p) {
      const sim::Vec2 o{rng.uniform(-5, 305), rng.uniform(-5, 305)};
      check_same(w, caster, o, random_layers(rng), sim::Ray::kNoTurtle, rng);
    }
    // A ray along a wall's line from beyond its end: only the end (a point) is met, 0.5 away.
    const sim::WallDef* seen = nullptr;
    for (const sim::WallDef& wd : def.walls)
      if (!seen && wd.layers.collides_with(sim::Layers{})) seen = &wd;
    if (seen) {
      const sim::WallDef& wd = *seen;  // axis-aligned, so the origin is on its line exactly
      // From beyond its `to` end, which no other wall shares.
      const sim::Vec2 dir = wd.from - wd.to, o = wd.to - dir / sim::norm(dir) * 0.5;
      std::vector<sim::RayHit> got;
      caster.cast(w, o, sim::Layers{}, sim::Ray::kNoTurtle, {dir}, {10.0}, 10.0, got);
      sim::Ray ray;
      ray.origin = o;
      ray.dir = dir;
      ray.range = 10.0;
      const sim::RayHit want = w.cast_ray(ray);
      CHECK(got[0].distance == want.distance);
      CHECK(got[0].target == want.target);
      CHECK(got[0].index == want.index);
      CHECK(want.target == sim::RayTarget::wall_end);
      CHECK(want.distance == 0.5);
      hits += want.hit();
    }
  }
  CHECK(hits > 0);
}

TEST_CASE("RingCaster: declines periodic arenas, moving or timed walls and many walls") {
  sim::WorldDef def;
  def.arena = {100, 100, {}, sim::Boundary::walls};
  def.turtles.push_back({"t", {50, 50}});
  {
    sim::World w(def, sim::Mode::exact);
    CHECK(RingCaster::applies(w, def));
    CHECK(!RingCaster::applies(w, def, 3));  // the arena's four walls
  }
  sim::WorldDef periodic = def;
  periodic.arena.boundary = sim::Boundary::periodic;
  CHECK(!RingCaster::applies(sim::World(periodic, sim::Mode::exact), periodic));
  sim::WorldDef moving = def;
  sim::WallDef m{"m", {10, 10}, {10, 30}};
  m.keys.push_back({1.0, {12, 10}, {12, 30}});
  moving.walls.push_back(m);
  CHECK(!RingCaster::applies(sim::World(moving, sim::Mode::exact), moving));
}
