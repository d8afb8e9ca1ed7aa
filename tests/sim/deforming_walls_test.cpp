// SPDX-License-Identifier: MIT
// Walls that turn and stretch between keyframes: the bracketed time of impact against brute force
// and against the translation's closed form, exact strikes worked out by hand, and a stirred gas
// that never overlaps a paddle.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "scenes.hpp"
#include "turtlegas/sim/toi.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

namespace {

// The signed distance from the disc's centre to the line of the deforming segment, and whether the
// foot lies on the segment. Written independently of the engine (the line through both ends).
struct Brute {
  Vec2 rel, v, a, d0, w;
  double r;
  Vec2 centre(double t) const { return rel + t * v + (0.5 * t * t) * a; }
  Vec2 end2(double t) const { return d0 + t * w; }
  double signed_distance(double t) const {
    const Vec2 e = end2(t), c = centre(t);
    return (e.x * c.y - e.y * c.x) / std::hypot(e.x, e.y);
  }
  bool on_segment(double t) const {
    const Vec2 e = end2(t), c = centre(t);
    const double s = (e.x * c.x + e.y * c.y) / (e.x * e.x + e.y * e.y);
    return s >= 0 && s <= 1;
  }
  // First fall of the distance to r on either side (from outside to inside) with the foot on the
  // segment, by sampling M points and bisecting the first bracket; kNever if none.
  double first(double t_max, int M) const {
    double prev = signed_distance(0);
    for (int k = 1; k <= M; ++k) {
      const double t = t_max * k / M;
      const double d = signed_distance(t);
      for (double side : {1.0, -1.0}) {
        auto gap = [&](double tt) { return side * signed_distance(tt) - r; };
        if (side * prev - r > 0 && side * d - r <= 0) {
          double lo = t_max * (k - 1) / M, hi = t;
          for (int it = 0; it < 200; ++it) {
            const double m = 0.5 * (lo + hi);
            if (m <= lo || m >= hi) break;
            (gap(m) > 0 ? lo : hi) = m;
          }
          if (on_segment(lo)) return lo;
        }
      }
      prev = d;
    }
    return kNever;
  }
};

}  // namespace

TEST_CASE("deforming segment: with w = 0 the bracketed time equals the translation's closed form", "[deforming][toi]") {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  int hits = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Vec2 d0{10 * u(rng), 10 * u(rng)};
    const Vec2 rel{20 * u(rng), 20 * u(rng)};
    const Vec2 v = -0.2 * rel + Vec2{5 * u(rng), 5 * u(rng)};  // mostly towards the wall's region
    const Vec2 a = trial % 2 ? Vec2{0, -9.81} : Vec2{};
    const double r = 0.5 + std::abs(u(rng));
    const Segment s = make_segment({0, 0}, d0);
    if (std::abs(cross(d0, rel)) / norm(d0) <= r) continue;  // starts within reach of the line
    const double closed = toi_disc_segment(rel, v, a, s, r);
    const double bracketed = toi_disc_deforming_segment(rel, v, a, d0, {}, r, 100.0);
    INFO("trial " << trial);
    if (closed > 100.0) {
      CHECK(bracketed == kNever);
    } else {
      ++hits;
      CHECK(bracketed == Approx(closed).epsilon(1e-12).margin(1e-12));
    }
  }
  CHECK(hits > 2000);
}

TEST_CASE("deforming segment: the bracketed time agrees with dense sampling", "[deforming][toi]") {
  std::mt19937_64 rng(272);
  std::uniform_real_distribution<double> u(-1, 1);
  int hits = 0, misses = 0, far_side = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Vec2 rel{15 * u(rng), 15 * u(rng)};
    Brute b{rel, -0.4 * rel + Vec2{4 * u(rng), 4 * u(rng)}, trial % 3 == 0 ? Vec2{0, -5} : Vec2{},
            {10 * u(rng), 10 * u(rng)}, {6 * u(rng), 6 * u(rng)}, 0.5 + std::abs(u(rng))};
    const double t_max = 2.0;
    // The span must stay clear of zero (validate() guarantees it for keyframed walls).
    bool degenerate = false;
    for (int k = 0; k <= 100; ++k) degenerate = degenerate || norm(b.end2(t_max * k / 100)) < 0.5;
    if (degenerate || std::abs(b.signed_distance(0)) <= b.r) continue;
    const double brute = b.first(t_max, 200000);
    const double fast = toi_disc_deforming_segment(b.rel, b.v, b.a, b.d0, b.w, b.r, t_max);
    INFO("trial " << trial << " brute " << brute << " fast " << fast);
    if (brute == kNever) {
      ++misses;
      CHECK(fast == kNever);
    } else {
      ++hits;
      CHECK(fast == Approx(brute).margin(1e-10));
      // Never inside: the returned time is the outside end of the bracket.
      CHECK(std::abs(b.signed_distance(fast)) - b.r >= -1e-12);
      far_side += b.signed_distance(fast) * b.signed_distance(0) < 0;
    }
  }
  CHECK(hits > 300);
  CHECK(misses > 300);
  CHECK(far_side > 10);  // contacts on the face the disc did not start on
}

TEST_CASE("deforming segment: touching and approaching is a contact now, touching and receding never", "[deforming][toi]") {
  // A disc of radius 1 resting on the line y = 0 (centre at y = 1); the wall tilts up under it.
  const Vec2 rel{5, 1}, d0{10, 0};
  CHECK(toi_disc_deforming_segment(rel, {}, {}, d0, {0, 1}, 1.0, 1.0) == 0.0);
  CHECK(toi_disc_deforming_segment(rel, {}, {}, d0, {0, -1}, 1.0, 1.0) == kNever);
  // Receding now, but the wall turns back under a ball thrown up and falling again: that contact
  // is found (the wall reaches the tilt of d0 + 2w at t = 2, with the ball back at y = 1).
  const double t = toi_disc_deforming_segment(rel, {0, 10}, {0, -10}, d0, {0, 0.0}, 1.0, 5.0);
  CHECK(t == Approx(2.0).epsilon(1e-12));
}

TEST_CASE("a wall swinging about one end strikes a ball at rest at the time and speed worked out by hand", "[deforming]") {
  for (Mode mode : {Mode::exact, Mode::step}) {
    INFO((mode == Mode::exact ? "exact" : "step"));
    // The second end moves in a straight line from (10, 0) to (0, 10) in 1 s: the end is at
    // 10 (1 - t, t). A ball of radius 0.5 at (3, 3) is at distance 3 |1 - 2t| / sqrt(1 - 2t + 2t^2) from
    // the line, which falls to 0.5 where 35.5 t^2 - 35.5 t + 8.75 = 0.
    WorldDef d = box(40, 40, Boundary::none);
    d.dt = 0.05;
    d.walls.push_back(moving("arm", {0, 0}, {10, 0}, {{1.0, {0, 0}, {0, 10}}}));
    d.balls.push_back(ball("b", {3, 3}, {0, 0}, 0.5));
    World w(d, mode);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.advance_to(0.9);
    REQUIRE(!log.empty());
    const double t = (35.5 - std::sqrt(17.75)) / 71.0;
    CHECK(log[0].kind == EventKind::ball_wall);
    CHECK(log[0].t == Approx(t).epsilon(1e-12));
    // At the contact the arm points along (1 - t, t); the foot is at s = 3 / (10 ((1 - t)^2 + t^2)) of
    // it, moving at s (-10, 10); the ball leaves with twice that velocity's normal component.
    const Vec2 dir = Vec2{1 - t, t} / std::hypot(1 - t, t);
    const Vec2 n{dir.y, -dir.x};  // the ball's side (below the arm's line as it swings up)
    const double s = 3.0 / (10.0 * ((1 - t) * (1 - t) + t * t));
    const Vec2 uc = s * Vec2{-10, 10};
    const Vec2 expected = 2.0 * dot(uc, n) * n;
    const Vec2 got = w.ball(0).vel;
    CHECK(got.x == Approx(expected.x).epsilon(1e-10));
    CHECK(got.y == Approx(expected.y).epsilon(1e-10));
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}

TEST_CASE("a wall stretching along its line hits a ball with its moving end", "[deforming]") {
  // The second end moves from (10, 0) to (30, 0) in 10 s, at (2, 0). A ball of radius 1 at rest at
  // (20, 0.5): the end touches it when (20 - x)^2 + 0.25 = 1, x = 20 - sqrt(0.75).
  WorldDef d = box(40, 40, Boundary::none);
  d.walls.push_back(moving("rod", {0, 0}, {10, 0}, {{10.0, {0, 0}, {30, 0}}}));
  d.balls.push_back(ball("b", {20, 0.5}, {0, 0}, 1.0));
  World w(d, Mode::exact);
  std::vector<Event> log;
  w.set_event_log(&log);
  w.advance_to(6.0);
  REQUIRE(log.size() == 1);
  CHECK(log[0].kind == EventKind::ball_wall_end);
  CHECK(log[0].t == Approx((10 - std::sqrt(0.75)) / 2).epsilon(1e-12));
  // In the end's frame the ball comes at (-2, 0) and bounces off the normal (sqrt(.75), .5).
  CHECK(w.ball(0).vel.x == Approx(3.0).epsilon(1e-12));
  CHECK(w.ball(0).vel.y == Approx(std::sqrt(3.0)).epsilon(1e-12));
}

TEST_CASE("a ball bouncing on a wall that only stretches keeps its speed", "[deforming][physics]") {
  // The surface moves along itself: no normal velocity, so no work is done on the ball.
  WorldDef d = box(100, 100, Boundary::none);
  d.walls.push_back(moving("floor", {10, 10}, {30, 10}, {{20.0, {0, 10}, {90, 10}}}));
  d.balls.push_back(ball("b", {20, 50}, {0.5, -10}, 1.0));
  d.effects.gravity = {0, -9.81};
  World w(d, Mode::exact);
  const double e0 = w.energy();
  w.advance_to(19.0);
  CHECK(w.stats().ball_wall >= 3);
  CHECK(w.energy() == Approx(e0).epsilon(1e-11));
}

TEST_CASE("a paddle turning in a box stirs a gas: no overlap, no escape, energy grows, runs are reproducible", "[deforming][physics]") {
  WorldDef d = random_gas(120, 0.12, 0.5, 1.0, 9);
  const double side = d.arena.width;
  const Vec2 c{side / 2, side / 2};
  // Remove the balls the paddle would start inside, then make it turn a full circle in eight
  // keyframes per turn, four turns.
  const double half = side * 0.3;
  std::erase_if(d.balls, [&](const BallDef& b) { return std::abs(b.pos.y - c.y) < 1.2 && std::abs(b.pos.x - c.x) < half + 1.2; });
  WallDef paddle{"paddle", c - Vec2{half, 0}, c + Vec2{half, 0}};
  for (int k = 1; k <= 32; ++k) {
    const double ang = k * M_PI / 4;
    const Vec2 arm{half * std::cos(ang), half * std::sin(ang)};
    paddle.keys.push_back({k * 2.0, c - arm, c + arm});
  }
  d.walls.push_back(paddle);
  World w(d, Mode::exact);
  std::vector<Event> log;
  w.set_event_log(&log);
  const double e0 = w.energy();
  double worst = 0;
  for (int k = 1; k <= 700; ++k) {
    w.advance_to(k * 0.1);
    worst = std::max(worst, w.measure_overlap().relative);
  }
  CHECK(worst <= 1e-9);
  CHECK(w.stats().exits == 0);
  CHECK(w.energy() > 1.5 * e0);
  for (std::size_t i = 0; i < w.ball_count(); ++i) {
    const Vec2 p = w.ball(i).pos;
    CHECK((p.x > 0 && p.x < side && p.y > 0 && p.y < side));
  }
  std::size_t on_paddle = 0;
  for (const Event& e : log) on_paddle += (e.kind == EventKind::ball_wall || e.kind == EventKind::ball_wall_end) && e.b == 0;  // the scene's walls come first
  CHECK(on_paddle > 50);
  // One call or many: the same events, bit for bit.
  World again(d, Mode::exact);
  std::vector<Event> log2;
  again.set_event_log(&log2);
  again.advance_to(70.0);
  REQUIRE(log2.size() == log.size());
  bool same = true;
  for (std::size_t k = 0; k < log.size(); ++k)
    same = same && log[k].t == log2[k].t && log[k].kind == log2[k].kind && log[k].a == log2[k].a && log[k].b == log2[k].b;
  CHECK(same);
}

TEST_CASE("a turtle struck by a turning wall is touched and knocked away", "[deforming][turtle]") {
  WorldDef d = box(200, 200, Boundary::none);
  // An arm from (100, 100) swinging from pointing +x to pointing +y in 2 s.
  d.walls.push_back(moving("arm", {100, 100}, {180, 100}, {{2.0, {100, 100}, {100, 180}}}));
  d.turtles.push_back(turtle("t", {150, 120}, 0, 5));
  World w(d, Mode::exact);
  w.advance_to(1.0);
  const auto contacts = w.take_turtle_contacts();
  REQUIRE(contacts.size() == 1);
  CHECK(contacts[0].kind == EventKind::turtle_wall);
  // Knocked off at twice the arm's normal speed at the contact: moving away from the arm.
  const Vec2 v = w.turtle(0).vel;
  CHECK(dot(v, contacts[0].normal) > 0.0);  // the normal points from the wall to the turtle
  CHECK(norm(v) > 0.0);
  CHECK(w.measure_overlap().relative <= 1e-9);
  // After the keyframe the arm stands still and so does the turtle.
  w.advance_to(3.0);
  CHECK(norm(w.turtle(0).vel) == 0.0);
  CHECK(w.measure_overlap().relative <= 1e-9);
}
