// SPDX-License-Identifier: MIT
// Ray casts (ray_cast.hpp, World::cast_ray): the closed forms against geometry worked by hand
// (tangent rays, 1e-12 inside a disc, rays along a wall's line, 1e6 units from the origin), and
// the grid walk against a brute-force reference over every body, wall and wall end (and their
// periodic images) on random rays: walled, open and periodic arenas, both modes, between events,
// rays along cell lines, through seams, with layers, invisible walls and turtles, moving walls.
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <random>
#include <stdexcept>
#include <vector>

#include "scenes.hpp"
#include "turtlegas/sim/ray_cast.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas;
using namespace turtlegas::test;
using sim::Ray;
using sim::RayHit;
using sim::RayTarget;

namespace {

/// The first hit by brute force: every live ball and turtle, every wall and both its ends (as
/// points), each at every periodic image the ray can reach; layers from the scene.
RayHit reference(const sim::World& w, const WorldDef& def, const Ray& ray) {
  const Vec2 u = ray.dir / sim::norm(ray.dir);
  RayHit best;
  auto consider = [&](double d, RayTarget target, std::uint32_t index) {
    if (!(d <= ray.range)) return;
    if (d < best.distance || (d == best.distance && (target < best.target || (target == best.target && index < best.index))))
      best = {d, target, index};
  };
  const bool periodic = def.arena.boundary == sim::Boundary::periodic;
  const double W = def.arena.width, H = def.arena.height;
  const int kx = periodic ? static_cast<int>(std::ceil((ray.range + std::fabs(ray.origin.x)) / W)) + 1 : 0;
  const int ky = periodic ? static_cast<int>(std::ceil((ray.range + std::fabs(ray.origin.y)) / H)) + 1 : 0;
  for (int jy = -ky; jy <= ky; ++jy)
    for (int jx = -kx; jx <= kx; ++jx) {
      const Vec2 shift{jx * W, jy * H};
      for (std::size_t i = 0; i < w.ball_count(); ++i) {
        const sim::BallState b = w.ball(i);
        if (!b.alive || !ray.layers.collides_with(def.balls[i].layers)) continue;
        consider(sim::ray_disc(b.pos + shift - ray.origin, u, w.radius(i)), RayTarget::ball, static_cast<std::uint32_t>(i));
      }
      for (std::size_t k = 0; k < w.turtle_count(); ++k) {
        if (!w.turtle_alive(k) || k == ray.self || !ray.layers.collides_with(def.turtles[k].layers)) continue;
        consider(sim::ray_disc(w.turtle(k).pos + shift - ray.origin, u, w.turtle_radius(k)), RayTarget::turtle,
                 static_cast<std::uint32_t>(k));
      }
      for (std::size_t k = 0; k < w.walls().size(); ++k) {
        const sim::WallDef& wall = w.walls()[k];
        if (!sim::wall_visible(wall, w.time())) continue;
        if (!ray.layers.collides_with(wall.layers)) continue;
        const sim::WallKey pose = sim::wall_pose(wall, w.time());
        const sim::Segment s = sim::make_segment(pose.from + shift, pose.to + shift);
        const auto index = static_cast<std::uint32_t>(k);
        consider(sim::ray_segment(ray.origin - s.p1, u, s), RayTarget::wall, index);
        consider(sim::ray_point(ray.origin - (pose.from + shift), u), RayTarget::wall_end, index);
        consider(sim::ray_point(ray.origin - (pose.to + shift), u), RayTarget::wall_end, index);
      }
    }
  return best;
}

/// Whether two answers agree: the same distance to 1e-9 (relative, or absolute below 1), and the
/// same object unless two objects are hit at that same distance.
bool same(const RayHit& a, const RayHit& b) {
  if (a.hit() != b.hit()) return false;
  if (!a.hit()) return true;
  if (std::fabs(a.distance - b.distance) > 1e-9 * std::max(1.0, b.distance)) return false;
  return (a.target == b.target && a.index == b.index) || std::fabs(a.distance - b.distance) <= 1e-9 * std::max(1.0, b.distance);
}

const char* name(RayTarget t) {
  switch (t) {
    case RayTarget::none: return "none";
    case RayTarget::wall: return "wall";
    case RayTarget::wall_end: return "wall_end";
    case RayTarget::ball: return "ball";
    case RayTarget::turtle: return "turtle";
  }
  return "?";
}

}  // namespace

TEST_CASE("ray_disc: the closed form, tangent rays and rays a hair inside", "[rays]") {
  // A disc of radius 5 centred 50 ahead and 3 aside: d = 50 - sqrt(25 - 9) = 46.
  CHECK(sim::ray_disc({50, 3}, {1, 0}, 5.0) == Approx(46.0).epsilon(1e-15));
  CHECK(sim::ray_disc({-50, 3}, {1, 0}, 5.0) == sim::kNever);  // behind
  CHECK(sim::ray_disc({50, 5}, {1, 0}, 5.0) == sim::kNever);   // tangent: no hit
  CHECK(sim::ray_disc({50, 6}, {1, 0}, 5.0) == sim::kNever);
  // 1e-12 inside the tangent: a hit, at the tangent point's distance (50 - sqrt(1e-11) ~ 49.9999968).
  const double d = sim::ray_disc({50, 5 - 1e-12}, {1, 0}, 5.0);
  REQUIRE(d < sim::kNever);
  CHECK(std::fabs(d - (50.0 - std::sqrt(5.0 * 5.0 - (5 - 1e-12) * (5 - 1e-12)))) < 1e-9);
  CHECK(sim::ray_disc({1, 1}, {0, 1}, 5.0) == 0.0);  // origin inside the disc
  // Random rays: the hit point lies on the circle and is the nearer root.
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  int hits = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec2 rel{200 * U(rng), 200 * U(rng)};
    const double a = M_PI * U(rng);
    const Vec2 u{std::cos(a), std::sin(a)};
    const double r = 1 + 20 * (U(rng) + 1);
    const double d = sim::ray_disc(rel, u, r);
    const double b = sim::dot(rel, u), c = sim::cross(rel, u);
    if (sim::norm(rel) <= r) {
      CHECK(d == 0.0);
    } else if (b > 0 && std::fabs(c) < r) {
      ++hits;
      const double exact = b - std::sqrt(r * r - c * c);
      INFO("k " << k);
      CHECK(std::fabs(d - exact) <= 1e-12 * std::max(1.0, exact) + 1e-9);
      CHECK(std::fabs(sim::norm(d * u - rel) - r) < 1e-9 * r);
    } else {
      CHECK(d == sim::kNever);
    }
  }
  CHECK(hits > 800);
}

TEST_CASE("ray_segment and ray_point: crossings, ends, and rays along the wall's line", "[rays]") {
  const sim::Segment s = sim::make_segment({10, -5}, {10, 5});
  CHECK(sim::ray_segment(Vec2{0, 0} - s.p1, {1, 0}, s) == Approx(10.0).epsilon(1e-15));
  CHECK(sim::ray_segment(Vec2{20, 0} - s.p1, {-1, 0}, s) == Approx(10.0).epsilon(1e-15));  // from the other side
  CHECK(sim::ray_segment(Vec2{20, 0} - s.p1, {1, 0}, s) == sim::kNever);                   // away
  // At 45 degrees: crosses x = 10 at y = 10, off the segment; towards (10, 5) exactly: the end.
  const double r2 = std::sqrt(0.5);
  CHECK(sim::ray_segment(Vec2{0, 0} - s.p1, {r2, r2}, s) == sim::kNever);
  CHECK(sim::ray_segment(Vec2{0, 0} - s.p1, sim::Vec2{10, 5} / std::sqrt(125.0), s) ==
        Approx(std::sqrt(125.0)).epsilon(1e-14));
  // Grazing the end: 1e-12 past it misses, 1e-12 inside hits.
  CHECK(sim::ray_segment(Vec2{0, 5 + 1e-12} - s.p1, {1, 0}, s) == sim::kNever);
  CHECK(sim::ray_segment(Vec2{0, 5 - 1e-12} - s.p1, {1, 0}, s) == Approx(10.0).epsilon(1e-15));
  // Along the wall's own line: the segment is never crossed, its near end is a point hit.
  CHECK(sim::ray_segment(Vec2{10, -20} - s.p1, {0, 1}, s) == sim::kNever);
  CHECK(sim::ray_point(Vec2{10, -20} - Vec2{10, -5}, {0, 1}) == 15.0);
  CHECK(sim::ray_point(Vec2{10, -20} - Vec2{10, -5}, {0, -1}) == sim::kNever);
  CHECK(sim::ray_point(Vec2{10 + 1e-12, -20} - Vec2{10, -5}, {0, 1}) == sim::kNever);
}

TEST_CASE("cast_ray: a ray of range 1e308 out of an open arena ends, even at 180 degrees (sin = 1.2e-16)", "[rays]") {
  WorldDef def = box(400, 400);
  def.arena.boundary = sim::Boundary::none;
  def.balls.push_back(ball("b", {300, 300}, {0, 0}, 5));
  const sim::World w(def, sim::Mode::exact);
  // Before, the walk stepped x until the ray's y crossing 1e17 units on: it never returned. Bounded
  // here by a thread: a hang fails the test instead of stalling the suite.
  auto cast = std::async(std::launch::async, [&] {
    std::vector<RayHit> hits;
    for (const double deg : {0.0, 90.0, 180.0, 270.0, 45.0})
      hits.push_back(w.cast_ray(Ray{{200, 200}, {std::cos(deg * M_PI / 180), std::sin(deg * M_PI / 180)}, 1e308}));
    return hits;
  });
  if (cast.wait_for(std::chrono::seconds(20)) != std::future_status::ready) {
    std::fprintf(stderr, "cast_ray did not return in 20 s\n");
    std::_Exit(1);
  }
  const std::vector<RayHit> hits = cast.get();
  for (std::size_t k = 0; k < 4; ++k) CHECK_FALSE(hits[k].hit());
  REQUIRE(hits[4].hit());  // 45 degrees: the ball at (300, 300)
  CHECK(hits[4].distance == Approx(100 * std::sqrt(2.0) - 5).epsilon(1e-12));
}

TEST_CASE("cast_ray: closed forms in a world, layers, invisibility, self, 1e6 from the origin", "[rays]") {
  WorldDef def = box(400, 400);
  def.walls.push_back({"w", {300, 100}, {300, 300}});
  def.balls.push_back(ball("b", {150, 203}, {0, 0}, 5));
  def.turtles.push_back(turtle("t0", {50, 200}, 90));
  def.turtles.push_back(turtle("t1", {50, 100}, 90));
  sim::World w(def, sim::Mode::exact);
  Ray ray;
  ray.origin = {50, 200};
  ray.dir = {1, 0};
  ray.self = 0;
  RayHit h = w.cast_ray(ray);
  CHECK(h.target == RayTarget::ball);
  CHECK(h.index == 0);
  CHECK(h.distance == Approx(100.0 - 4.0).epsilon(1e-14));  // 100 - sqrt(25 - 9)
  ray.range = 95.0;
  CHECK_FALSE(w.cast_ray(ray).hit());
  ray.range = sim::kNever;
  ray.origin = {50, 260};  // above the ball: the wall at x = 300
  h = w.cast_ray(ray);
  CHECK(h.target == RayTarget::wall);
  CHECK(h.distance == 250.0);
  ray.origin = {50, 350};  // above the wall: the arena's right wall (index 1 + 1: arena-right)
  h = w.cast_ray(ray);
  CHECK(h.target == RayTarget::wall);
  CHECK(w.walls()[h.index].id == "arena-right");
  CHECK(h.distance == 350.0);
  // A turtle sees the other turtle, never itself.
  ray.origin = {50, 200};
  ray.dir = {0, -1};
  h = w.cast_ray(ray);
  CHECK(h.target == RayTarget::turtle);
  CHECK(h.index == 1);
  CHECK(h.distance == Approx(90.0).epsilon(1e-14));
  ray.self = 1;
  h = w.cast_ray(ray);
  CHECK(h.target == RayTarget::turtle);
  CHECK(h.index == 0);
  CHECK(h.distance == 0.0);  // the origin is inside turtle 0
  CHECK_THROWS_AS(w.cast_ray(Ray{{1, 1}, {0, 0}}), std::invalid_argument);
  CHECK_THROWS_AS(w.cast_ray(Ray{{1, 1}, {1, 0}, -1.0}), std::invalid_argument);

  // Layers: a wall not there for the ray's layers, an invisible turtle, a wall switched off.
  WorldDef lay = box(400, 400);
  lay.walls.push_back({"glass", {300, 100}, {300, 300}});
  lay.walls.back().layers = {2, 0xffffffffu & ~4u};  // does not collide with category 4
  lay.walls.push_back({"ghostly", {350, 100}, {350, 300}});
  lay.walls.back().visibility = {{0.0, false}};
  lay.turtles.push_back(turtle("seer", {50, 200}, 90));
  lay.turtles.back().layers = {4, 0xffffffffu};
  lay.turtles.push_back(turtle("ghost", {150, 200}, 90));
  lay.turtles.back().layers = {8, 1u | 2u};  // collides with walls only: invisible to turtles
  sim::World lw(lay, sim::Mode::exact);
  Ray seer{{50, 200}, {1, 0}, sim::kNever, {4, 0xffffffffu}, 0};
  h = lw.cast_ray(seer);
  CHECK(h.target == RayTarget::wall);
  CHECK(lw.walls()[h.index].id == "arena-right");
  CHECK(h.distance == 350.0);
  Ray plain{{50, 200}, {1, 0}};
  plain.self = 0;
  h = lw.cast_ray(plain);  // the default layers are the walls' category, which the ghost meets
  CHECK(h.target == RayTarget::turtle);
  CHECK(h.index == 1);
  CHECK(h.distance == Approx(90.0).epsilon(1e-14));
  plain.origin = {50, 250};
  h = lw.cast_ray(plain);  // and the glass, which category 4 passes through
  CHECK(h.target == RayTarget::wall);
  CHECK(lw.walls()[h.index].id == "glass");
  CHECK(h.distance == 250.0);

  // 1e6 units from the origin: the same geometry, shifted.
  WorldDef far = box(2.1e6, 2.1e6);
  far.balls.push_back(ball("b", {1e6 + 100, 1e6 + 3}, {0, 0}, 5));
  far.walls.push_back({"w", {1e6 + 300, 1e6 - 100}, {1e6 + 300, 1e6 + 100}});
  sim::World fw(far, sim::Mode::exact);
  h = fw.cast_ray(Ray{{1e6 + 4, 1e6}, {1, 0}});
  CHECK(h.target == RayTarget::ball);
  CHECK(std::fabs(h.distance - 92.0) < 1e-9);
  h = fw.cast_ray(Ray{{1e6 + 4, 1e6 + 50}, {1, 0}});
  CHECK(h.target == RayTarget::wall);
  CHECK(std::fabs(h.distance - 296.0) < 1e-9);
}

TEST_CASE("cast_ray through a periodic arena's seams", "[rays]") {
  WorldDef def = box(300, 300, sim::Boundary::periodic);
  def.balls.push_back(ball("b", {20, 150}, {0, 0}, 5));
  def.walls.push_back({"w", {150, 250}, {150, 290}});
  sim::World w(def, sim::Mode::exact);
  // From x = 280 to the right: across the seam at 300 to the ball at 320 (image), d = 40 - 5.
  RayHit h = w.cast_ray(Ray{{280, 150}, {1, 0}, 1000.0});
  CHECK(h.target == RayTarget::ball);
  CHECK(h.distance == Approx(35.0).epsilon(1e-14));
  // Left from x = 100 at y = 270: the wall's image at x = 150 - 300 = -150 is 250 away.
  h = w.cast_ray(Ray{{100, 270}, {-1, 0}, 1000.0});
  CHECK(h.target == RayTarget::wall);
  CHECK(h.distance == 250.0);
  // Downwards at x = 150 from y = 100: through the seam at y = 0 to the wall's top end at
  // y = 290 - 300 = -10 (a point, along the wall's line): 110.
  h = w.cast_ray(Ray{{150, 100}, {0, -1}, 1000.0});
  CHECK(h.target == RayTarget::wall_end);
  CHECK(h.distance == Approx(110.0).epsilon(1e-14));
  CHECK_FALSE(w.cast_ray(Ray{{150, 100}, {0, -1}, 109.0}).hit());
  CHECK_THROWS_AS(w.cast_ray(Ray{{150, 100}, {0, -1}}), std::invalid_argument);  // infinite in a periodic arena
}

/// The scene of the random-ray cases: a gas of 500 discs, four inner walls with ends of their own,
/// two turtles (one invisible to turtles), a moving wall unless periodic.
WorldDef ray_scene(sim::Boundary boundary, std::uint64_t seed) {
  WorldDef def = random_gas(500, 0.12, 3.0, 60.0, seed, boundary);
  const double W = def.arena.width, H = def.arena.height;
  // Some balls taken out to make room for walls and turtles; walls with ends of their own.
  for (int k = 0; k < 4; ++k) {
    const double y = (0.2 + 0.2 * k) * H;
    def.walls.push_back({"iw" + std::to_string(k), {0.3 * W + 7 * k, y}, {0.6 * W, y + 0.05 * H}});
  }
  def.turtles.push_back(turtle("ta", {0.5 * W, 0.5 * H}, 30, 8));
  def.turtles.push_back(turtle("tb", {0.25 * W, 0.7 * H}, 200, 8));
  def.turtles.back().layers = {2, 1u};  // sees walls and balls only: invisible to turtles
  if (boundary != sim::Boundary::periodic)
    def.walls.push_back(moving("mover", {0.1 * W, 0.9 * H}, {0.2 * W, 0.95 * H}, {{5.0, {0.1 * W, 0.8 * H}, {0.25 * W, 0.9 * H}}}));
  std::erase_if(def.balls, [&](const BallDef& b) {
    for (const auto& t : def.turtles)
      if (sim::norm(b.pos - t.pos) < b.radius + t.radius + 2) return true;
    for (const auto& wd : def.walls) {
      const sim::Segment s = sim::make_segment(wd.from, wd.to);
      const Vec2 rel = b.pos - s.p1;
      const double foot = std::clamp(sim::dot(rel, s.u), 0.0, s.len);
      if (sim::norm(rel - foot * s.u) < b.radius + 2) return true;
    }
    return false;
  });
  for (auto& b : def.balls) b.vel = 0.2 * b.vel;  // keep the mover clear for the run
  return def;
}

TEST_CASE("cast_ray equals the brute-force reference on random rays", "[rays]") {
  for (sim::Boundary boundary : {sim::Boundary::walls, sim::Boundary::periodic, sim::Boundary::none}) {
    for (sim::Mode mode : {sim::Mode::exact, sim::Mode::step}) {
      const std::uint64_t seed = 31 + static_cast<int>(boundary) * 10 + (mode == sim::Mode::step);
      INFO("boundary " << static_cast<int>(boundary) << ", mode " << (mode == sim::Mode::step ? "step" : "exact")
                       << ", seed " << seed);
      const WorldDef def = ray_scene(boundary, seed);
      const double W = def.arena.width, H = def.arena.height;
      std::mt19937_64 rng(seed);
      auto uni = [&](double a, double b) { return a + (b - a) * (static_cast<double>(rng() >> 11) * 0x1.0p-53); };
      sim::World w(def, mode);
      const double cell = w.cell_size();
      std::size_t hits = 0, checked = 0;
      for (int step = 1; step <= 6; ++step) {
        w.advance_to(step * 0.2 + (step % 2 ? w.dt() / 3 : 0.0));
        for (int q = 0; q < 400; ++q) {
          Ray ray;
          ray.origin = {uni(-0.1 * W, 1.1 * W), uni(-0.1 * H, 1.1 * H)};
          const double a = uni(0, 2 * M_PI);
          ray.dir = {std::cos(a), std::sin(a)};
          if (q % 8 == 0) ray.dir = {q % 16 ? 1.0 : -1.0, 0.0};
          if (q % 8 == 1) ray.dir = {0.0, q % 16 ? -1.0 : 1.0};
          if (q % 8 == 2) ray.origin.x = std::floor(ray.origin.x / cell) * cell, ray.dir = {0.0, 1.0};  // along a cell line
          ray.range = q % 3 == 0 ? uni(0, 0.3 * W) : (boundary == sim::Boundary::periodic ? 2.5 * W : sim::kNever);
          if (q % 5 == 0) ray.layers = def.turtles[1].layers, ray.self = 1;
          if (q % 5 == 1) ray.origin = w.turtle(0).pos, ray.self = 0;
          const RayHit got = w.cast_ray(ray);
          const RayHit want = reference(w, def, ray);
          INFO("t " << w.time() << " ray " << q << " from (" << ray.origin.x << ", " << ray.origin.y << ") dir (" << ray.dir.x
                    << ", " << ray.dir.y << ") range " << ray.range << ": got " << name(got.target) << " " << got.index
                    << " at " << got.distance << ", want " << name(want.target) << " " << want.index << " at "
                    << want.distance);
          CHECK(same(got, want));
          ++checked;
          hits += want.hit();
        }
      }
      CHECK(hits > checked / 2);
    }
  }
}

TEST_CASE("cast_rays gives cast_ray's answers, bit for bit, for rings and fans of rays", "[rays]") {
  for (sim::Boundary boundary : {sim::Boundary::walls, sim::Boundary::periodic, sim::Boundary::none}) {
    for (sim::Mode mode : {sim::Mode::exact, sim::Mode::step}) {
      const std::uint64_t seed = 71 + static_cast<int>(boundary) * 10 + (mode == sim::Mode::step);
      INFO("boundary " << static_cast<int>(boundary) << ", mode " << (mode == sim::Mode::step ? "step" : "exact")
                       << ", seed " << seed);
      const WorldDef def = ray_scene(boundary, seed);
      const double W = def.arena.width, H = def.arena.height;
      std::mt19937_64 rng(seed);
      auto uni = [&](double a, double b) { return a + (b - a) * (static_cast<double>(rng() >> 11) * 0x1.0p-53); };
      sim::World w(def, mode);
      const double cell = w.cell_size();
      std::size_t hits = 0, checked = 0;
      std::vector<Vec2> dirs;
      std::vector<RayHit> got;
      for (int step = 1; step <= 6; ++step) {
        w.advance_to(step * 0.2 + (step % 2 ? w.dt() / 3 : 0.0));
        for (int q = 0; q < 150; ++q) {
          Ray ray;
          ray.origin = {uni(-0.1 * W, 1.1 * W), uni(-0.1 * H, 1.1 * H)};
          if (q % 7 == 0) ray.origin = {std::floor(ray.origin.x / cell) * cell, std::floor(ray.origin.y / cell) * cell};  // a cell corner
          // Mostly sensor ranges (a few cells); some long, some 0.
          ray.range = q % 10 == 0 ? uni(0, 0.5 * W) : q % 10 == 1 ? 0.0 : uni(0, 3 * cell);
          if (q % 5 == 0) ray.layers = def.turtles[1].layers, ray.self = 1;
          if (q % 5 == 1) ray.origin = w.turtle(0).pos, ray.self = 0;
          const int n = 1 + q % 24;
          const double a0 = uni(0, 2 * M_PI);
          dirs.clear();
          for (int k = 0; k < n; ++k) dirs.push_back({std::sin(a0 + 2 * M_PI * k / n), std::cos(a0 + 2 * M_PI * k / n)});
          if (q % 4 == 2) dirs.push_back({1.0, 0.0}), dirs.push_back({0.0, -1.0});  // along the cell lines
          w.cast_rays(ray, dirs.data(), dirs.size(), got);
          REQUIRE(got.size() == dirs.size());
          for (std::size_t k = 0; k < dirs.size(); ++k) {
            Ray one = ray;
            one.dir = dirs[k];
            const RayHit want = w.cast_ray(one);
            INFO("t " << w.time() << " fan " << q << " ray " << k << " from (" << ray.origin.x << ", " << ray.origin.y
                      << ") dir (" << one.dir.x << ", " << one.dir.y << ") range " << ray.range << ": got "
                      << name(got[k].target) << " " << got[k].index << " at " << got[k].distance << ", want "
                      << name(want.target) << " " << want.index << " at " << want.distance);
            // Bit for bit: the same distance (kNever when nothing), target and index.
            CHECK(got[k].distance == want.distance);
            CHECK((!want.hit() || (got[k].target == want.target && got[k].index == want.index)));
            ++checked;
            hits += want.hit();
          }
        }
      }
      CHECK(hits > checked / 4);
    }
  }
}
