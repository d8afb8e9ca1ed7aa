// SPDX-License-Identifier: MIT
// Small scenes built in code for the engine tests (world files are tested through the loader).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "turtlegas/sim/world.hpp"

namespace turtlegas::test {

using sim::BallDef;
using sim::Vec2;
using sim::WallDef;
using sim::WorldDef;

inline WorldDef box(double w, double h, sim::Boundary boundary = sim::Boundary::walls) {
  WorldDef d;
  d.name = "test";
  d.arena.width = w;
  d.arena.height = h;
  d.arena.boundary = boundary;
  return d;
}

/// A wall moving through keyframes (see WallDef::keys).
inline WallDef moving(std::string id, Vec2 from, Vec2 to, std::vector<sim::WallKey> keys) {
  WallDef w{std::move(id), from, to};
  w.keys = std::move(keys);
  return w;
}

inline BallDef ball(std::string id, Vec2 pos, Vec2 vel, double radius = 1.0, double mass = 1.0) {
  return BallDef{std::move(id), pos, vel, radius, mass, 0.0};
}

/// A turtle with the given heading (degrees, Logo convention), radius and speed; turn rate 90°/s.
inline sim::TurtleDef turtle(std::string id, Vec2 pos, double heading_deg, double radius = 10, double speed = 30) {
  sim::TurtleDef t;
  t.id = std::move(id);
  t.pos = pos;
  t.heading = heading_deg * (M_PI / 180.0);
  t.radius = radius;
  t.speed = speed;
  t.turn_rate = M_PI / 2;
  return t;
}

/// A random gas on a jittered lattice (never overlapping), speeds `speed` in random directions.
inline WorldDef random_gas(int n, double phi, double radius, double speed, std::uint64_t seed,
                           sim::Boundary boundary = sim::Boundary::walls) {
  const double side = std::sqrt(n * M_PI * radius * radius / phi);
  WorldDef d = box(side, side, boundary);
  std::mt19937_64 rng(seed);
  auto uniform = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  const int per_row = static_cast<int>(std::ceil(std::sqrt(n)));
  const double pitch = side / per_row;
  const double slack = std::max(0.0, pitch - 2.0 * radius) * 0.49;
  for (int i = 0; i < n; ++i) {
    const int row = i / per_row, col = i % per_row;
    const Vec2 centre{(col + 0.5) * pitch, (row + 0.5) * pitch};
    const Vec2 jitter{(2 * uniform() - 1) * slack, (2 * uniform() - 1) * slack};
    const double a = 2 * M_PI * uniform();
    d.balls.push_back(ball("g" + std::to_string(i), centre + jitter, {speed * std::cos(a), speed * std::sin(a)}, radius));
  }
  return d;
}

inline double momentum_x(const sim::World& w) {
  double p = 0;
  for (std::size_t i = 0; i < w.ball_count(); ++i) p += w.mass(i) * w.ball(i).vel.x;
  return p;
}

/// Advances w to `until` in `samples` equal slices; the deepest overlap (relative to a radius)
/// seen at any slice's end.
inline double deepest_over_run(sim::World& w, double until, int samples) {
  double worst = 0.0;
  for (int k = 1; k <= samples; ++k) {
    w.advance_to(until * k / samples);
    worst = std::max(worst, w.measure_overlap().relative);
  }
  return worst;
}

}  // namespace turtlegas::test
