// SPDX-License-Identifier: MIT
// gas_soak: a long run of a dense gas (area fraction 0.5) checked as it goes (issue 17, section
// 7). Two scenes, exact mode, e = 1:
//   still:  a walled box; every check, energy included (it is conserved: drift must stay < 1e-10);
//   moving: the box widened by two strips, with a piston in each sweeping in and out (400
//           keyframes); the walls do work, so energy is not checked, the rest is.
// Every `every` events: the deepest overlap (World::measure_overlap, exact over all pairs and
// walls) against 1e-9 of a radius, NaN in any position or velocity, balls outside the box, and
// the energy drift. Prints one line per check and a summary; exit 1 on the first failure.
//
//   gas_soak [still|moving] [collisions, default 1e8] [every, default 1e6] [balls, default 4096]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;

namespace {

WorldDef dense_gas(int n, bool moving, std::uint64_t seed) {
  // A square lattice of spacing r sqrt(2 pi) has area fraction 0.5; radius 1.
  const double r = 1.0, d = r * std::sqrt(2.0 * M_PI);
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  const double box = side * d;
  WorldDef def;
  def.name = moving ? "soak-moving" : "soak-still";
  def.arena.width = box + (moving ? 4 * d : 0.0);
  def.arena.height = box;
  def.arena.boundary = Boundary::walls;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double x0 = moving ? 2 * d : 0.0;
  for (int k = 0; k < n; ++k) {
    const int column = k % side, row = k / side;  // a square lattice, filled row by row
    const Vec2 p{x0 + (column + 0.5) * d, (row + 0.5) * d};
    def.balls.push_back({"b" + std::to_string(k), p, {gauss(rng), gauss(rng)}, r, 1.0, 0.0});
  }
  if (moving) {
    // Pistons in the free strips at both ends, sweeping 1.4 d in and back out every 20 s; the gas
    // is never squeezed shut.
    const double W = def.arena.width, H = def.arena.height;
    WallDef left{"left", {0.5 * d, 0.0}, {0.5 * d, H}};
    WallDef right{"right", {W - 0.5 * d, 0.0}, {W - 0.5 * d, H}};
    for (int c = 1; c <= 400; ++c) {
      const double t = 10.0 * c;
      const double x = c % 2 == 1 ? 1.9 * d : 0.5 * d;
      left.keys.push_back({t, {x, 0.0}, {x, H}});
      right.keys.push_back({t, {W - x, 0.0}, {W - x, H}});
    }
    def.walls.push_back(left);
    def.walls.push_back(right);
  }
  return def;
}

bool finite(Vec2 v) { return std::isfinite(v.x) && std::isfinite(v.y); }

}  // namespace

int main(int argc, char** argv) {
  const std::string scene = argc > 1 ? argv[1] : "still";
  const double target = argc > 2 ? std::atof(argv[2]) : 1e8;
  const double every = argc > 3 ? std::atof(argv[3]) : 1e6;
  const int n = argc > 4 ? std::atoi(argv[4]) : 4096;
  if (scene != "still" && scene != "moving") {
    std::fprintf(stderr, "usage: gas_soak [still|moving] [collisions] [every] [balls]\n");
    return 2;
  }
  const bool moving = scene == "moving";
  const WorldDef def = dense_gas(n, moving, 17);
  World w(def, Mode::exact);
  const double e0 = w.energy();
  const double W = def.arena.width, H = def.arena.height;
  const auto start = std::chrono::steady_clock::now();
  double worst_overlap = 0.0, worst_drift = 0.0;
  std::uint64_t checks = 0;
  // Advance in slices of simulated time sized to about `every` events each.
  double t = 0.0, slice = 1.0;
  std::uint64_t last_events = 0;
  while (static_cast<double>(w.stats().collisions()) < target) {
    t += slice;
    w.advance_to(t);
    const std::uint64_t ev = w.stats().events;
    const double got = static_cast<double>(ev - last_events);
    last_events = ev;
    if (got > 0) slice *= std::clamp(every / got, 0.5, 2.0);
    ++checks;
    const Overlap o = w.measure_overlap();
    worst_overlap = std::max(worst_overlap, o.relative);
    bool nan = false, escaped = false;
    for (std::size_t i = 0; i < w.ball_count(); ++i) {
      const BallState b = w.ball(i);
      nan |= !finite(b.pos) || !finite(b.vel);
      escaped |= !b.alive || b.pos.x < 0.0 || b.pos.x > W || b.pos.y < 0.0 || b.pos.y > H;
    }
    const double drift = std::abs(w.energy() - e0) / e0;
    if (!moving) worst_drift = std::max(worst_drift, drift);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("t %.6g collisions %.4g events %.4g overlap %.3g drift %.3g nan %d escaped %d (%.0f s)\n", t,
                static_cast<double>(w.stats().collisions()), static_cast<double>(ev), o.relative, drift, nan, escaped,
                secs);
    std::fflush(stdout);
    if (o.relative > 1e-9 || nan || escaped || (!moving && drift > 1e-10)) {
      std::printf("FAIL at t %.17g\n", t);
      return 1;
    }
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  char drift_text[32];
  std::snprintf(drift_text, sizeof drift_text, "%.3g", worst_drift);
  std::printf("ok: %s, %d balls, phi 0.5, %.4g collisions in %.4g s of simulated time, %llu checks; "
              "worst overlap %.3g of a radius, worst energy drift %s, no NaN, no escape (%.0f s)\n",
              scene.c_str(), n, static_cast<double>(w.stats().collisions()), t, static_cast<unsigned long long>(checks),
              worst_overlap, moving ? "(not checked: the walls do work)" : drift_text, secs);
  return 0;
}
