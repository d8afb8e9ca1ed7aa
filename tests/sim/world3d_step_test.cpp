// SPDX-License-Identifier: MIT
// 3-D step mode (docs/physics.md, "3-D: step mode"): straight flights with exact contacts inside
// each step and the fields' kick v += a dt at its end. The discrete trajectory in closed form, the
// same run as exact mode without a field, first-order convergence to exact mode, and a gas under
// gravity that never overlaps.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "turtlegas/sim/world3d.hpp"

using namespace turtlegas::sim;

namespace {

World3Def falling(double dt) {
  World3Def def;
  def.size = {100, 100, 100};
  def.gravity = {0, 0, -10};
  def.mode = Mode::step;
  def.dt = dt;
  def.spheres.push_back({{50, 50, 80}, {1, -0.5, 2}, 1.0, 1.0, 0.0});
  return def;
}

// A sphere bouncing elastically on a floor under gravity, with a sideways speed.
World3Def bouncing(Mode mode, double dt) {
  World3Def def;
  def.size = {40, 40, 40};
  def.boundary = Boundary3::walls;
  def.gravity = {0, 0, -9.81};
  def.mode = mode;
  def.dt = dt;
  def.spheres.push_back({{5, 20, 12}, {0.7, 0.3, 0}, 1.0, 1.0, 0.0});
  return def;
}

}  // namespace

TEST_CASE("3-D step mode: a free flight is the drift-then-kick sequence, x_n = x0 + n v0 dt + a dt^2 n (n - 1) / 2") {
  for (const double dt : {1.0 / 64, 1.0 / 30}) {
    const World3Def def = falling(dt);
    World3 w(def);
    const int n = 45;
    const double t = n * dt;
    w.advance_to(t);
    const Vec3 x0 = def.spheres[0].pos, v0 = def.spheres[0].vel, a = def.gravity;
    for (int k = 0; k < 3; ++k) {
      CHECK(w.position(0)[k] == Approx(x0[k] + n * v0[k] * dt + a[k] * dt * dt * n * (n - 1) / 2.0).epsilon(1e-13));
      CHECK(w.velocity(0)[k] == Approx(v0[k] + n * a[k] * dt).epsilon(1e-13).margin(1e-13));
    }
    // Between step ends the sphere flies straight at the velocity of its last kick.
    w.advance_to(t + dt / 4);
    CHECK(w.position(0).z == Approx(x0.z + n * v0.z * dt + a.z * dt * dt * n * (n - 1) / 2.0 + (v0.z + n * a.z * dt) * dt / 4)
                                 .epsilon(1e-13));
  }
}

TEST_CASE("3-D step mode: its error against the parabola is a dt T / 2, first order in dt") {
  // Exact: z(T) = z0 + v0 T + a T^2 / 2. Step: z0 + v0 T + a T (T - dt) / 2. The difference is -a dt T / 2.
  const double T = 1.5;
  double previous = 0.0;
  for (const double dt : {1.0 / 16, 1.0 / 32, 1.0 / 64, 1.0 / 128}) {
    const World3Def def = falling(dt);
    World3 step(def);
    World3Def exact_def = def;
    exact_def.mode = Mode::exact;
    World3 exact(exact_def);
    step.advance_to(T);
    exact.advance_to(T);
    const double err = step.position(0).z - exact.position(0).z;
    CHECK(err == Approx(-def.gravity.z * dt * T / 2).epsilon(1e-9));
    if (previous != 0.0) CHECK(previous / err == Approx(2.0).epsilon(1e-9));
    previous = err;
  }
}

TEST_CASE("3-D step mode without a field is exact mode's run, contact for contact") {
  World3Def def;
  def.size = {12, 12, 12};
  def.boundary = Boundary3::walls;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        def.spheres.push_back({{2.0 + 4.0 * i, 2.0 + 4.0 * j, 2.0 + 4.0 * k}, {u(rng), u(rng), u(rng)}, 0.8, 1.0, 0.0});
  def.walls.push_back({{{1, 1, 7.5}, {11, 1, 8}, {11, 11, 8.5}, {1, 11, 8}}});
  World3Def step_def = def;
  step_def.mode = Mode::step;
  step_def.dt = 0.05;
  World3 exact(def), step(step_def);
  std::vector<Event3> a, b;
  exact.advance_to(40.0, &a);
  step.advance_to(40.0, &b);
  REQUIRE(a.size() > 200);
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    CHECK(a[i].t == b[i].t);
    CHECK(a[i].a == b[i].a);
  }
  for (std::size_t i = 0; i < def.spheres.size(); ++i) {
    CHECK(exact.position(i) == step.position(i));
    CHECK(exact.velocity(i) == step.velocity(i));
  }
}

TEST_CASE("3-D step mode: a sphere bouncing on a floor meets it dt/2 late, to within a dt^2 / 4v") {
  // Dropped from z = 12 onto the floor (centre at z = 1), a = 9.81: exact mode meets it at
  // t1 = sqrt(22 / a) with speed v1 = a t1. At step ends z_step(n dt) = z(n dt - dt/2) + a dt^2 / 8
  // (z the exact fall), and between them the step path is the chord, within a dt^2 / 8 of the
  // shifted parabola: so the step run meets the floor at t1 + dt/2 to within a dt^2 / (4 v1).
  // Over 12 s (four bounces) it stays within a dt T of exact mode and never overlaps the floor.
  const double a = 9.81, T = 12.0;
  const double t1 = std::sqrt(22.0 / a), v1 = a * t1;
  for (const double dt : {1.0 / 30, 1.0 / 100, 1.0 / 200, 1.0 / 400, 1.0 / 800}) {
    World3 step(bouncing(Mode::step, dt));
    World3 ref(bouncing(Mode::exact, 1.0));
    std::vector<Event3> log;
    double worst = 0.0, err = 0.0;
    for (int k = 1; k <= 2400; ++k) {
      step.advance_to(T * k / 2400, &log);
      ref.advance_to(T * k / 2400);
      worst = std::max(worst, step.max_overlap_now());
      const Vec3 d = step.position(0) - ref.position(0);
      err = std::max(err, std::sqrt(dot(d, d)));
    }
    INFO("dt " << dt << ": largest distance from exact mode " << err);
    REQUIRE(log.size() == 4);
    CHECK(std::abs(log[0].t - (t1 + dt / 2)) <= a * dt * dt / (4 * v1) + 1e-12);
    CHECK(worst <= 1e-12);
    CHECK(err < a * dt * T);
  }
}

TEST_CASE("3-D step mode: a gas under gravity in a box keeps its spheres apart and its energy near") {
  World3Def def;
  def.size = {10, 10, 10};
  def.boundary = Boundary3::walls;
  def.gravity = {0, -2, 0};
  def.mode = Mode::step;
  def.dt = 1.0 / 60;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k)
        def.spheres.push_back({{1.25 + 2.5 * i, 1.25 + 2.5 * j, 1.25 + 2.5 * k}, {u(rng), u(rng), u(rng)}, 0.5, 1.0, 0.0});
  World3 w(def);
  const double e0 = w.energy();
  double worst = 0.0, drift = 0.0;
  for (int k = 1; k <= 600; ++k) {
    w.advance_to(k * 0.05);
    worst = std::max(worst, w.max_overlap_now());
    drift = std::max(drift, std::abs(w.energy() - e0));
  }
  CHECK(w.collisions() > 1000);
  CHECK(worst <= 1e-9);
  // Drift-kick (symplectic Euler) keeps the energy within O(m |a| |v| dt) of its start per sphere
  // and does not let it wander: 64 spheres, |a| = 2, |v| ~ 2, dt = 1/60 gives ~ 4.3.
  CHECK(drift / std::abs(e0) < 0.05);
}

TEST_CASE("3-D step mode refuses a dt that is not finite and > 0") {
  World3Def def = falling(0.0);
  CHECK_THROWS_WITH(World3(def), Catch::Contains("dt"));
  def.dt = std::nan("");
  CHECK_THROWS_WITH(World3(def), Catch::Contains("dt"));
}
