// SPDX-License-Identifier: MIT
// The time-of-impact and response functions against the memo's 2-D scalar formulas (AI Memo 272,
// "Wall Collisions" and "Ball Collisions"), on random inputs with a fixed seed.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "turtlegas/sim/toi.hpp"

using namespace turtlegas::sim;

namespace {

constexpr std::uint64_t kSeed = 20261121;

struct Rng {
  std::mt19937_64 gen{kSeed};
  double uniform(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(gen() >> 11) * 0x1.0p-53; }
};

// The memo's scalar ball-wall formula: the time at which the ball touches the infinite wall line,
// with the +/- taken opposite the sign of the denominator.
double memo_wall_time(double x1, double y1, double x2, double y2, double x0, double y0, double u, double v, double r) {
  const double l = std::hypot(x2 - x1, y2 - y1);
  const double den = u * (y2 - y1) - v * (x2 - x1);
  const double pm = den > 0 ? -1.0 : 1.0;
  return (pm * l * r - x0 * (y2 - y1) + y0 * (x2 - x1) - (x2 * y1 - x1 * y2)) / den;
}
// The memo's test that the contact lies on the real wall.
bool memo_wall_hit(double x1, double y1, double x2, double y2, double xt, double yt) {
  const double l2 = (x2 - x1) * (x2 - x1) + (y2 - y1) * (y2 - y1);
  return std::abs(x1 * x1 + y1 * y1 - x2 * x2 - y2 * y2 + 2 * (xt * (x2 - x1) + yt * (y2 - y1))) <= l2;
}
// The memo's wall-end time [i = 1, 2]; NaN when the radicand is negative.
double memo_end_time(double xi, double yi, double x0, double y0, double u, double v, double r) {
  const double rad = r * r * (u * u + v * v) - std::pow((x0 - xi) * v - (y0 - yi) * u, 2);
  if (rad < 0) return NAN;
  return -((x0 - xi) * u + (y0 - yi) * v + std::sqrt(rad)) / (u * u + v * v);
}
// The memo's ball-ball time. As transcribed, the memo writes (u1 - u2) in the first term; that gives
// -12 instead of 8 for a ball at the origin moving at (1, 0) towards a resting ball 10 away (radii
// 1), so the first term must read (u2 - u1), as the memo's own vector form -(x.v + ...) has it.
double memo_ball_time(double x1, double y1, double x2, double y2, double u1, double v1, double u2, double v2,
                      double r1, double r2) {
  const double du = u1 - u2, dv = v1 - v2;
  const double rad = std::pow(r1 + r2, 2) * (du * du + dv * dv) - std::pow((x2 - x1) * dv - (y2 - y1) * du, 2);
  if (rad < 0) return NAN;
  return -((x2 - x1) * (u2 - u1) + (y2 - y1) * (v2 - v1) + std::sqrt(rad)) / (du * du + dv * dv);
}

}  // namespace

TEST_CASE("ball-wall time and hit test agree with the memo's scalar formulas", "[toi][memo]") {
  Rng rng;
  int compared = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec2 a{rng.uniform(-100, 100), rng.uniform(-100, 100)}, b{rng.uniform(-100, 100), rng.uniform(-100, 100)};
    const Vec2 x{rng.uniform(-150, 150), rng.uniform(-150, 150)}, v{rng.uniform(-10, 10), rng.uniform(-10, 10)};
    const double r = rng.uniform(0.1, 5);
    const Segment s = make_segment(a, b);
    const Vec2 rel = x - a;
    const double foot = std::clamp(dot(rel, s.u), 0.0, s.len);
    if (norm(rel - foot * s.u) <= r) continue;  // start clear of the wall
    const double mine = toi_disc_segment(rel, v, {}, s, r);
    const double memo = memo_wall_time(a.x, a.y, b.x, b.y, x.x, x.y, v.x, v.y, r);
    const bool hit = memo > 0 && memo_wall_hit(a.x, a.y, b.x, b.y, x.x + v.x * memo, x.y + v.y * memo);
    INFO("seed " << kSeed << " case " << k);
    if (hit) {
      // Both are closed forms of the same root; they differ by round-off of a few ulps of the
      // numerator's terms, which are at most ~ |x| |b - a| ~ 3e4, relative to |den| t.
      REQUIRE(mine == Approx(memo).epsilon(1e-9).margin(1e-12));
      ++compared;
    } else {
      REQUIRE(mine == kNever);
    }
  }
  CHECK(compared > 1000);
}

TEST_CASE("wall response equals the memo's reflection by 2 theta", "[toi][memo]") {
  Rng rng;
  for (int k = 0; k < 5000; ++k) {
    const Vec2 a{rng.uniform(-100, 100), rng.uniform(-100, 100)}, b{rng.uniform(-100, 100), rng.uniform(-100, 100)};
    const Vec2 v{rng.uniform(-10, 10), rng.uniform(-10, 10)};
    const double l2 = norm2(b - a);
    const double s2 = 2 * (b.x - a.x) * (b.y - a.y) / l2;
    const double c2 = ((b.x - a.x) * (b.x - a.x) - (b.y - a.y) * (b.y - a.y)) / l2;
    const Vec2 memo{v.x * c2 + v.y * s2, v.x * s2 - v.y * c2};
    const Vec2 mine = respond_wall(v, make_segment(a, b).n, 1.0);
    REQUIRE(mine.x == Approx(memo.x).margin(1e-12));
    REQUIRE(mine.y == Approx(memo.y).margin(1e-12));
  }
}

TEST_CASE("wall-end time and response agree with the memo", "[toi][memo]") {
  Rng rng;
  int compared = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec2 p{rng.uniform(-100, 100), rng.uniform(-100, 100)};
    const Vec2 x{rng.uniform(-120, 120), rng.uniform(-120, 120)}, v{rng.uniform(-10, 10), rng.uniform(-10, 10)};
    const double r = rng.uniform(0.1, 20);
    if (norm(x - p) <= r) continue;
    const double mine = toi_disc_point(x - p, v, r);
    const double memo = memo_end_time(p.x, p.y, x.x, x.y, v.x, v.y, r);
    INFO("seed " << kSeed << " case " << k);
    if (!std::isnan(memo) && memo > 0) {
      REQUIRE(mine == Approx(memo).epsilon(1e-9).margin(1e-12));
      ++compared;
      const Vec2 F = x + mine * v - p;
      const double s2 = 2 * F.x * F.y / norm2(F), c2 = (F.x * F.x - F.y * F.y) / norm2(F);
      const Vec2 memo_v{-v.x * c2 - v.y * s2, v.y * c2 - v.x * s2};
      const Vec2 mine_v = respond_point(v, F, 1.0);
      REQUIRE(mine_v.x == Approx(memo_v.x).margin(1e-9));
      REQUIRE(mine_v.y == Approx(memo_v.y).margin(1e-9));
    } else {
      REQUIRE(mine == kNever);
    }
  }
  CHECK(compared > 500);
}

TEST_CASE("ball-ball time and response agree with the memo", "[toi][memo]") {
  Rng rng;
  int compared = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec2 x1{rng.uniform(-50, 50), rng.uniform(-50, 50)}, x2{rng.uniform(-50, 50), rng.uniform(-50, 50)};
    const Vec2 v1{rng.uniform(-10, 10), rng.uniform(-10, 10)}, v2{rng.uniform(-10, 10), rng.uniform(-10, 10)};
    const double r1 = rng.uniform(0.5, 8), r2 = rng.uniform(0.5, 8);
    const double m1 = rng.uniform(0.1, 10), m2 = rng.uniform(0.1, 10);
    if (norm(x2 - x1) <= r1 + r2) continue;
    const double mine = toi_disc_disc(x2 - x1, v2 - v1, r1 + r2);
    const double memo = memo_ball_time(x1.x, x1.y, x2.x, x2.y, v1.x, v1.y, v2.x, v2.y, r1, r2);
    INFO("seed " << kSeed << " case " << k);
    if (!std::isnan(memo) && memo > 0) {
      REQUIRE(mine == Approx(memo).epsilon(1e-9).margin(1e-12));
      ++compared;
      // The memo's response: reflect each velocity relative to the centre of mass by 2 theta.
      const Vec2 F = (x2 + mine * v2) - (x1 + mine * v1);
      const double s2 = 2 * F.x * F.y / norm2(F), c2 = (F.x * F.x - F.y * F.y) / norm2(F);
      const Vec2 vc = (m1 * v1 + m2 * v2) / (m1 + m2);
      auto memo_v = [&](Vec2 vi) {
        const Vec2 w = vi - vc;
        return Vec2{-w.x * c2 - w.y * s2 + vc.x, w.y * c2 - w.x * s2 + vc.y};
      };
      Vec2 a = v1, b = v2;
      respond_disc_disc(a, b, m1, m2, F, 1.0);
      REQUIRE(a.x == Approx(memo_v(v1).x).margin(1e-9));
      REQUIRE(a.y == Approx(memo_v(v1).y).margin(1e-9));
      REQUIRE(b.x == Approx(memo_v(v2).x).margin(1e-9));
      REQUIRE(b.y == Approx(memo_v(v2).y).margin(1e-9));
    } else {
      REQUIRE(mine == kNever);
    }
  }
  CHECK(compared > 1000);
}

TEST_CASE("ball-ball collisions conserve momentum and energy", "[response]") {
  Rng rng;
  for (int k = 0; k < 10000; ++k) {
    const double m1 = rng.uniform(0.01, 100), m2 = rng.uniform(0.01, 100);
    Vec2 v1{rng.uniform(-10, 10), rng.uniform(-10, 10)}, v2{rng.uniform(-10, 10), rng.uniform(-10, 10)};
    // Head-on for the first cases, oblique after.
    const Vec2 F = k < 100 ? Vec2{2.0, 0.0} : Vec2{rng.uniform(-2, 2), rng.uniform(-2, 2)};
    if (k < 100) v2.y = v1.y = 0;
    if (dot(v2 - v1, F) >= 0) continue;
    const Vec2 p0 = m1 * v1 + m2 * v2;
    const double e0 = 0.5 * m1 * norm2(v1) + 0.5 * m2 * norm2(v2);
    const Vec2 v1_in = v1, v2_in = v2;
    respond_disc_disc(v1, v2, m1, m2, F, 1.0);
    const Vec2 p1 = m1 * v1 + m2 * v2;
    const double e1 = 0.5 * m1 * norm2(v1) + 0.5 * m2 * norm2(v2);
    // Round-off: a handful of ulps of the largest momentum and energy terms.
    const double pscale = m1 * norm(v1_in) + m2 * norm(v2_in);
    REQUIRE(std::abs(p1.x - p0.x) <= 1e-14 * pscale);
    REQUIRE(std::abs(p1.y - p0.y) <= 1e-14 * pscale);
    REQUIRE(std::abs(e1 - e0) <= 1e-14 * e0 + 1e-300);
    // The normal relative velocity reverses.
    REQUIRE(dot(v2 - v1, F) == Approx(-dot(v2_in - v1_in, F)).epsilon(1e-12).margin(1e-12));
  }
}

TEST_CASE("equal masses head-on exchange velocities; unequal masses follow the 1-D formulas", "[response]") {
  Vec2 a{3, 0}, b{-1, 0};
  respond_disc_disc(a, b, 1, 1, {1, 0}, 1.0);
  CHECK(a.x == Approx(-1));
  CHECK(b.x == Approx(3));
  Vec2 c{4, 0}, d{0, 0};
  respond_disc_disc(c, d, 1, 3, {1, 0}, 1.0);
  CHECK(c.x == Approx((1.0 - 3.0) / 4.0 * 4));  // (m1 - m2)/(m1 + m2) u
  CHECK(d.x == Approx(2.0 * 1.0 / 4.0 * 4));    // 2 m1/(m1 + m2) u
}

TEST_CASE("inelastic responses scale the normal velocity by e and keep the tangential", "[response]") {
  const double e = 0.6;
  const Segment s = make_segment({0, 0}, {10, 0});
  const Vec2 v = respond_wall({2, -5}, s.n, e);
  CHECK(v.x == Approx(2));
  CHECK(v.y == Approx(3));
  const Vec2 w = respond_point({0, -5}, {0, 1}, e);
  CHECK(w.y == Approx(3));
  Vec2 a{1, 0}, b{-1, 0};
  respond_disc_disc(a, b, 1, 1, {1, 0}, e);
  CHECK(a.x == Approx(-0.6));
  CHECK(b.x == Approx(0.6));
}

TEST_CASE("first_approach_quadratic: the contact rules", "[roots]") {
  SECTION("approaching from outside") { CHECK(first_approach_quadratic(4, -2, 0) == Approx(2)); }
  SECTION("touching and approaching collides at once") { CHECK(first_approach_quadratic(0, -1, 0) == 0.0); }
  SECTION("overlapping by round-off and approaching collides at once") {
    CHECK(first_approach_quadratic(-1e-17, -1, 0) == 0.0);
  }
  SECTION("touching and receding never collides") { CHECK(first_approach_quadratic(0, 1, 0) == kNever); }
  SECTION("overlapping by round-off and receding never collides") {
    CHECK(first_approach_quadratic(-1e-17, 1, 0) == kNever);
  }
  SECTION("a graze is not a collision") {
    CHECK(first_approach_quadratic(0, 0, 0) == kNever);
    CHECK(first_approach_quadratic(1, -2, 1) == kNever);  // (t - 1)^2: double root
  }
  SECTION("thrown up, falls back: the descending root") {
    // 0 + 10 t - 5 t^2: leaves at 0, returns at 2.
    CHECK(first_approach_quadratic(0, 10, -5) == Approx(2));
    CHECK(first_approach_quadratic(-1e-15, 10, -5) == Approx(2));
  }
  SECTION("resting under a pull collides at once") { CHECK(first_approach_quadratic(0, 0, -5) == 0.0); }
  SECTION("no cancellation for a root near zero with a huge other root") {
    // f = 1e-10 - t + 1e-12 t^2: root ~ 1e-10 (naive formula loses all digits).
    const double t = first_approach_quadratic(1e-10, -1, 1e-12);
    CHECK(t == Approx(1e-10).epsilon(1e-14));
  }
}

TEST_CASE("first_approach_poly finds the first falling root of a quartic", "[roots]") {
  Rng rng;
  for (int k = 0; k < 3000; ++k) {
    // |p + v t + a t^2/2|^2 - r^2 for random flights, checked against dense sampling.
    const Vec2 p{rng.uniform(-5, 5), rng.uniform(-5, 5)}, v{rng.uniform(-3, 3), rng.uniform(-3, 3)},
        a{rng.uniform(-2, 2), rng.uniform(-2, 2)};
    const double r = rng.uniform(0.2, 2);
    if (norm(p) <= r) continue;
    const double t = toi_disc_point_accel(p, v, a, r, 20.0);
    auto f = [&](double s) { return norm(p + s * v + (0.5 * s * s) * a) - r; };
    double first = kNever;
    const int samples = 20000;
    for (int m = 1; m <= samples; ++m) {
      const double s = 20.0 * m / samples;
      if (f(s) < 0) {
        first = s;
        break;
      }
    }
    INFO("seed " << kSeed << " case " << k);
    if (first == kNever) {
      // Either no contact, or a touch shallower than the sampling resolves.
      if (t != kNever) REQUIRE(f(t) == Approx(0).margin(1e-9));
    } else {
      REQUIRE(t <= first);
      REQUIRE(t >= first - 20.0 / samples);
      REQUIRE(f(t) >= -1e-12);  // the returned time never overlaps
    }
  }
}

TEST_CASE("wall times stay exact far from the origin", "[toi][stability]") {
  // The same geometry at the origin and shifted by 1e6: computed relative to the wall, the time of
  // impact keeps its digits (an absolute formula would lose ~1e6 * eps / (r / v) of them).
  const Vec2 shift{1e6, -1e6};
  const Segment s0 = make_segment({0, 0}, {100, 0});
  const Segment s1 = make_segment(shift + Vec2{0, 0}, shift + Vec2{100, 0});
  // A gap of 2^-23 is exactly representable at 1e6 too, so both scenes are the same scene.
  const Vec2 x{50, 1.0 + 0x1p-23};
  const Vec2 v{0.3, -1.0};
  const double t0 = toi_disc_segment(x - s0.p1, v, {}, s0, 1.0);
  const double t1 = toi_disc_segment((shift + x) - s1.p1, v, {}, s1, 1.0);
  CHECK(t0 == Approx(0x1p-23).epsilon(1e-12));
  CHECK(t1 == Approx(t0).epsilon(1e-12));
}

TEST_CASE("under a field a disc passing a wall's line beyond an end can land on its other face", "[toi][gravity]") {
  // A shelf from (3, 10) to (13, 10); a ball of radius 0.5 thrown from (16.5, 8) at (-4, 8) under
  // g = 9.81 rises past the shelf's end (x = 15.6 when it reaches y = 9.5) and comes down on top of
  // it where 8 + 8 t - 4.905 t^2 = 10.5 on the way down: t = (8 + sqrt(64 - 49.05)) / 9.81.
  const Segment s = make_segment({3, 10}, {13, 10});
  const double t = toi_disc_segment(Vec2{16.5, 8} - s.p1, {-4, 8}, {0, -9.81}, s, 0.5);
  CHECK(t == Approx((8 + std::sqrt(64 - 49.05)) / 9.81).epsilon(1e-14));
  // Against dense sampling of the centre's height, on random throws past random shelves' ends.
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(-1, 1);
  int far_side = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Segment w = make_segment({0, 0}, {10, 0});
    const Vec2 rel{10 + 3 * std::abs(u(rng)), -2 - 2 * std::abs(u(rng))};
    const Vec2 v{-6 * std::abs(u(rng)), 6 + 6 * std::abs(u(rng))};
    const Vec2 a{0, -9.81};
    const double r = 0.5;
    // Sampled: the first time the centre is within r of the line, foot on the segment, having
    // come from outside.
    double sampled = kNever;
    double prev_gap = std::abs(rel.y) - r;
    const int M = 100000;
    for (int k = 1; k <= M && sampled == kNever; ++k) {
      const double tk = 4.0 * k / M;
      const Vec2 p = rel + tk * v + (0.5 * tk * tk) * a;
      const double gap = std::abs(p.y) - r;
      if (prev_gap > 0 && gap <= 0 && p.x >= 0 && p.x <= 10) sampled = tk;
      prev_gap = gap;
    }
    const double exact = toi_disc_segment(rel, v, a, w, r);
    INFO("trial " << trial);
    if (sampled > 4.0) {
      CHECK((exact == kNever || exact > 4.0 - 1e-4));
    } else {
      CHECK(exact == Approx(sampled).margin(4.0 / M));
      far_side += (rel + exact * v + (0.5 * exact * exact) * a).y > 0;
    }
  }
  CHECK(far_side > 100);
}
