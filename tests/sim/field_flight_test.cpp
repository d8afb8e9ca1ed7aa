// SPDX-License-Identifier: MIT
// Field flights (field_flight.hpp) against a 50-digit oracle written with the textbook formula
// the code avoids; the convention, the guiding centre, energy, moving frames and the step-mode
// kicks' orders of accuracy.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "field_oracle.hpp"
#include "turtlegas/sim/field_flight.hpp"

using namespace turtlegas::sim;
using field_oracle::Mp;

namespace {

constexpr std::uint64_t kSeed = 20261214;
constexpr double kEps = 2.220446049250313e-16;

double mp_dist(const field_oracle::V2<Mp>& a, Vec2 b) {
  const Mp dx = a.x - Mp(b.x), dy = a.y - Mp(b.y);
  return static_cast<double>(boost::multiprecision::sqrt(dx * dx + dy * dy));
}

// A random flight over the field ranges of the issue: q/m in [1e-6, 1e6], Bz in [1e-8, 1e6] (so
// |w| in [1e-14, 1e12]), E with a drift E/B of up to 10 speed units, gravity, any direction.
FieldFlight random_flight(field_oracle::Rng& rng, double* qm_out = nullptr) {
  const double qm = rng.sign() * rng.log_uniform(1e-6, 1e6);
  const double bz = rng.sign() * rng.log_uniform(1e-8, 1e6);
  const double speed = rng.log_uniform(1e-3, 1e3);
  FieldFlight f;
  f.w = qm * bz;
  f.v = speed * rng.direction();
  const int kind = static_cast<int>(rng.gen() % 4);
  const Vec2 e = rng.direction_then([&] { return (kind >= 2 ? rng.uniform(0.0, 10.0) * std::abs(bz) * speed : 0.0); });
  const Vec2 g = rng.direction_then([&] { return (kind % 2 == 1 ? rng.log_uniform(1e-3, 1e3) : 0.0); });
  f.a = g + qm * e;
  if (qm_out) *qm_out = qm;
  return f;
}

}  // namespace

TEST_CASE("field flights agree with a 50-digit oracle from tiny angles to 10^4 periods", "[field][flight]") {
  field_oracle::Rng rng(kSeed);
  double worst_x = 0.0, worst_v = 0.0;
  for (int k = 0; k < 4000; ++k) {
    const FieldFlight f = random_flight(rng);
    const Vec2 x0{rng.uniform(-100, 100), rng.uniform(-100, 100)};
    const double aw = std::abs(f.w);
    // theta = w t from 1e-20 to 10^4 periods, with t at most 1e6.
    const double theta = rng.log_uniform(1e-20, 2 * std::numbers::pi * 1e4);
    const double t = std::min(theta / aw, 1e6);
    const double th = aw * t;
    const FieldState mine{field_displacement(f, t), field_velocity(f, t)};
    const auto ref0 = field_oracle::mp_state(x0, f, Mp(t));
    const field_oracle::State<Mp> ref{ref0.x - field_oracle::lift<Mp>(x0), ref0.v};
    // The natural size of the displacement's terms, bounded without the code's own arrangement:
    // t |v| (1 + theta/2) + t^2 |a| (1/2 + theta/6) for small theta, 3 |v| / |w| + (theta + 3) |a| / w^2.
    const double nv = norm(f.v), na = norm(f.a);
    const double scale_x = std::min(t * nv * (1 + th / 2) + t * t * na * (0.5 + th / 6), 3 * nv / aw + (th + 3) * na / (aw * aw));
    const double scale_v = 1.5 * nv + std::min(t * na * (1 + th / 2), 3 * na / aw);
    // A few ulps per term, plus the phase error of w t (|v| t eps / 2).
    const double tol_x = (64 * kEps + 4 * kEps * th) * scale_x;
    const double tol_v = (64 * kEps + 4 * kEps * th) * scale_v;
    const double ex = mp_dist(ref.x, mine.x), ev = mp_dist(ref.v, mine.v);
    INFO("seed " << kSeed << " case " << k << " w " << f.w << " t " << t << " theta " << th);
    REQUIRE(std::isfinite(mine.x.x));
    REQUIRE(std::isfinite(mine.v.y));
    REQUIRE(ex <= tol_x);
    REQUIRE(ev <= tol_v);
    worst_x = std::max(worst_x, ex / scale_x);
    worst_v = std::max(worst_v, ev / scale_v);
  }
  // The bound is loose by design; the real errors are ulps.
  CHECK(worst_x < 1e-11);
  CHECK(worst_v < 1e-11);
}

TEST_CASE("after 10^4 periods positions and velocities keep 1e-9 of the orbit", "[field][flight]") {
  field_oracle::Rng rng(kSeed + 1);
  for (int k = 0; k < 500; ++k) {
    const FieldFlight f = random_flight(rng);
    const double period = gyration_period(f.w);
    const double t = (1e4 + rng.uniform(0, 1)) * period;
    const Vec2 x0{rng.uniform(-10, 10), rng.uniform(-10, 10)};
    const FieldState mine = field_advance(x0, f, t);
    const auto ref = field_oracle::mp_state(x0, f, Mp(t));
    const double rho = gyration_radius(f), ud = norm(drift_velocity(f));
    INFO("seed " << kSeed + 1 << " case " << k << " w " << f.w);
    // Relative to the orbit: its radius plus the distance drifted.
    REQUIRE(mp_dist(ref.x, mine.x) <= 1e-9 * (rho + ud * t) + 4 * kEps * norm(x0));
    REQUIRE(mp_dist(ref.v, mine.v) <= 1e-9 * (norm(f.v - drift_velocity(f)) + ud));
  }
}

TEST_CASE("a small w is never zero and tends to the parabola continuously", "[field][flight]") {
  const FieldFlight base{{1.5, -0.25}, {0.3, -9.81}, 0.0};
  const double t = 2.0;
  const Vec2 para = t * base.v + (0.5 * t * t) * base.a;
  CHECK(field_displacement(base, t) == para);
  double prev = kNever;
  for (int e = 1; e <= 40; ++e) {
    const double w = std::pow(10.0, -e);
    const FieldFlight f{base.v, base.a, w};
    const double diff = norm(field_displacement(f, t) - para);
    // The first-order term: w t^2 |v| / 2 + w t^3 |a| / 6, to within its own size.
    const double first = w * (t * t * norm(base.v) / 2 + t * t * t * norm(base.a) / 6);
    INFO("w = " << w);
    CHECK(diff <= 1.01 * first + 4 * kEps * norm(para));
    if (first > 1e3 * kEps * norm(para)) CHECK(diff >= 0.5 * first);  // a real effect, not lost
    CHECK(diff <= prev + 4 * kEps * norm(para));
    prev = diff;
  }
  // w = 1e-300: bit for bit the parabola's terms (theta underflows to a subnormal, nothing divides by it).
  const FieldFlight tiny{base.v, base.a, 1e-300};
  CHECK(norm(field_displacement(tiny, t) - para) <= 2 * kEps * norm(para));
  CHECK(norm(field_velocity(tiny, t) - (base.v + t * base.a)) <= 2 * kEps * norm(base.v + t * base.a));
}

TEST_CASE("the convention: a positive charge in Bz > 0 circles clockwise about its guiding centre", "[field][flight]") {
  // q/m = 2, Bz = 1: w = 2. Starting along +x at speed 1, a quarter period later it moves along -y.
  const FieldFlight f{{1, 0}, {}, 2.0};
  const double quarter = gyration_period(f.w) / 4;
  const Vec2 v = field_velocity(f, quarter);
  CHECK(v.x == Approx(0).margin(1e-15));
  CHECK(v.y == Approx(-1).epsilon(1e-15));
  // Clockwise: the centre is on the right of the velocity, below the start.
  const Vec2 c = guiding_centre({0, 0}, f);
  CHECK(c.x == Approx(0).margin(1e-16));
  CHECK(c.y == Approx(-0.5).epsilon(1e-15));
  CHECK(gyration_radius(f) == Approx(0.5).epsilon(1e-15));
  CHECK(cross(Vec2{0, 0} - c, f.v) < 0);  // angular momentum about the centre < 0: clockwise
}

TEST_CASE("guiding centre, drift, period and radius hold along random flights", "[field][flight]") {
  field_oracle::Rng rng(kSeed + 2);
  for (int k = 0; k < 2000; ++k) {
    const FieldFlight f = random_flight(rng);
    if (std::abs(f.w) < 1e-6) continue;  // the centre is then too far for a ulp-level check
    const Vec2 x0{rng.uniform(-10, 10), rng.uniform(-10, 10)};
    const Vec2 ud = drift_velocity(f);
    const double rho = gyration_radius(f);
    INFO("seed " << kSeed + 2 << " case " << k << " w " << f.w);
    // The drift solves a + w J(u) = 0.
    REQUIRE(norm(f.a + f.w * turn_cw(ud)) <= 4 * kEps * norm(f.a));
    const Vec2 c0 = guiding_centre(x0, f);
    const double scale = norm(x0) + rho + norm(ud) * gyration_period(f.w);
    for (double frac : {0.1, 0.37, 0.5, 0.99, 1.0, 7.3}) {
      const double t = frac * gyration_period(f.w);
      const FieldState s = field_advance(x0, f, t);
      // The centre moves at the drift; the body stays at the radius from it; |x''| is constant.
      const Vec2 c = guiding_centre(s.x, {s.v, f.a, f.w});
      REQUIRE(norm(c - (c0 + t * ud)) <= 1e-12 * scale);
      REQUIRE(std::abs(norm(s.x - c) - rho) <= 1e-12 * scale);
      REQUIRE(norm(field_acceleration({s.v, f.a, f.w})) == Approx(norm(field_acceleration(f))).epsilon(1e-12).margin(1e-300));
    }
    // After a whole period only the drift remains.
    const double p = gyration_period(f.w);
    REQUIRE(norm(field_displacement(f, p) - p * ud) <= 1e-12 * scale);
  }
}

TEST_CASE("energy: kinetic plus -m g.x - q E.x is conserved along every flight", "[field][flight][energy]") {
  field_oracle::Rng rng(kSeed + 3);
  for (int k = 0; k < 2000; ++k) {
    const double mass = rng.log_uniform(0.1, 10);
    const double qm = rng.sign() * rng.log_uniform(1e-6, 1e6);
    const double bz = rng.sign() * rng.log_uniform(1e-8, 1e6);
    const Vec2 v0 = rng.direction_then([&] { return rng.log_uniform(1e-2, 1e2); });
    const Vec2 e = rng.direction_then([&] { return rng.uniform(0, 3) * norm(v0) * std::abs(bz); });
    const Vec2 g = rng.direction_then([&] { return rng.uniform(0, 10); });
    const FieldFlight f{v0, g + qm * e, qm * bz};
    const Vec2 x0{rng.uniform(-10, 10), rng.uniform(-10, 10)};
    auto energy = [&](Vec2 x, Vec2 v) { return 0.5 * mass * norm2(v) + field_potential(x, mass, mass * qm, g, e); };
    const double e0 = energy(x0, v0);
    const double t = std::min(rng.uniform(0, 1e4) * gyration_period(f.w), 1e3);
    const FieldState s = field_advance(x0, f, t);
    // Scale: the kinetic energy's range over the orbit and the work of a over the displacement.
    const double vmax = norm(v0) + 2 * norm(f.v - (f.w != 0 ? drift_velocity(f) : Vec2{})) + norm(f.a) * std::min(t, 1.0);
    const double scale = 0.5 * mass * vmax * vmax + mass * norm(f.a) * (norm(x0) + norm(s.x - x0));
    INFO("seed " << kSeed + 3 << " case " << k);
    REQUIRE(std::abs(energy(s.x, s.v) - e0) <= 1e-11 * scale);
  }
}

TEST_CASE("a moving frame sees the extra electric field u x B", "[field][flight][frame]") {
  field_oracle::Rng rng(kSeed + 4);
  for (int k = 0; k < 1000; ++k) {
    const FieldFlight f = random_flight(rng);
    const Vec2 u = rng.direction_then([&] { return rng.log_uniform(1e-3, 1e3); });
    const double t = rng.uniform(0, 5) * std::min(gyration_period(f.w), 1e3);
    // Lab displacement minus the frame's equals the frame flight's displacement; velocities likewise.
    const Vec2 lab = field_displacement(f, t) - t * u;
    const Vec2 frame = field_displacement(in_moving_frame(f, u), t);
    const double scale = norm(field_displacement(f, t)) + t * norm(u) + norm(frame);
    INFO("seed " << kSeed + 4 << " case " << k);
    REQUIRE(norm(lab - frame) <= 1e-12 * scale + 1e-300);
    REQUIRE(norm((field_velocity(f, t) - u) - field_velocity(in_moving_frame(f, u), t)) <=
            1e-12 * (norm(field_velocity(f, t)) + norm(u)));
  }
}

TEST_CASE("relative motion is straight only without B and with equal accelerations", "[field][flight]") {
  CHECK(relative_motion_straight({{1, 0}, {0, -9.8}, 0}, {{0, 1}, {0, -9.8}, 0}));
  CHECK_FALSE(relative_motion_straight({{1, 0}, {0, -9.8}, 0}, {{0, 1}, {0, -9.7}, 0}));
  CHECK_FALSE(relative_motion_straight({{1, 0}, {}, 1e-300}, {{0, 1}, {}, 1e-300}));
  CHECK(wall_motion_straight({{1, 0}, {}, 0}));
  CHECK_FALSE(wall_motion_straight({{1, 0}, {0, -1e-300}, 0}));
}

namespace {

// Step mode on a free flight: n steps of dt, each a drift x += v dt and the kicks of `scheme`.
enum class Scheme { lie, strang, strang_split };
FieldState step_flight(Vec2 x, const FieldFlight& f, double t_end, int n, Scheme scheme) {
  const double dt = t_end / n;
  Vec2 v = f.v;
  auto split_kick = [&](Vec2 u, double h) { return rotation_kick(u + (0.5 * h) * f.a, f.w, h) + (0.5 * h) * f.a; };
  for (int i = 0; i < n; ++i) {
    switch (scheme) {
      case Scheme::lie:  // today's step mode: fly, then kick
        x += dt * v;
        v = field_kick(v, f.a, f.w, dt);
        break;
      case Scheme::strang:
        v = field_kick(v, f.a, f.w, 0.5 * dt);
        x += dt * v;
        v = field_kick(v, f.a, f.w, 0.5 * dt);
        break;
      case Scheme::strang_split:
        v = split_kick(v, 0.5 * dt);
        x += dt * v;
        v = split_kick(v, 0.5 * dt);
        break;
    }
  }
  return {x, v};
}

}  // namespace

TEST_CASE("step-mode kicks: drift-then-kick is first order, a half kick each side second order", "[field][step]") {
  // 1.3 periods of a charged ball in B with E and g (not a whole number: over whole periods the
  // drift's Riemann sum of a periodic velocity is exact to all orders and hides the error).
  const FieldFlight f{{1.0, 0.3}, {0.4, -0.8}, 2 * std::numbers::pi};
  const Vec2 x0{0.2, -0.1};
  const double t_end = 1.3;
  const FieldState exact = field_advance(x0, f, t_end);
  for (Scheme scheme : {Scheme::lie, Scheme::strang, Scheme::strang_split}) {
    const double order = scheme == Scheme::lie ? 1.0 : 2.0;
    double prev = 0.0;
    for (int n = 256; n <= 4096; n *= 2) {
      const FieldState s = step_flight(x0, f, t_end, n, scheme);
      const double err = norm(s.x - exact.x);
      if (prev > 0.0) {
        const double ratio = prev / err;
        INFO("scheme " << static_cast<int>(scheme) << " n " << n << " ratio " << ratio);
        CHECK(ratio == Approx(std::pow(2.0, order)).epsilon(0.01));
      }
      prev = err;
    }
  }
  // The rotation kick keeps |v| exactly up to rounding; the exact kick is the flight's velocity.
  const Vec2 v{3, -4};
  CHECK(norm(rotation_kick(v, 1e6, 0.37)) == Approx(5).epsilon(4 * kEps));
  CHECK(field_kick(v, f.a, f.w, 0.37) == field_velocity({v, f.a, f.w}, 0.37));
}
