// SPDX-License-Identifier: MIT
// A tiny, independent 3-D reference for tests only: no roots at all. Every body flies exactly
// (x + v t + a t^2 / 2); time advances by conservative advancement, each step no longer than the
// time any gap could close at its bounded rate (the distance to a sphere or to a convex polygon
// is 1-Lipschitz in position), so no contact can be stepped over; a contact is served when a gap
// is below 1e-12 of a radius and closing. The distance to a polygon is computed from scratch
// (inside test on the plane, else the nearest point of each edge), and the contact's kind from
// where the nearest point lies. O(N^2 + N W) per step: small scenes only. Restitution as
// docs/physics.md "3-D: restitution" states it, written from that text: a pair's e the larger of
// its spheres' (1 for one that changed course less than tc ago), a wall's the product, normal
// speeds leaving at 2^-40 of the speeds at least, and at |a_n| tc / 2 where pressed. Moving walls
// as "3-D: moving walls" states them: the shift interpolated between keys, distances to the
// shifted corners, steps that never pass a key, the bounce on the velocity relative to the wall.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <catch2/catch.hpp>

#include "turtlegas/sim/toi3.hpp"
#include "turtlegas/sim/vec3.hpp"
#include "turtlegas/sim/world3d.hpp"

namespace turtlegas::test3 {

using sim::Vec3;

struct Nearest {
  double dist;
  Vec3 point;
  sim::Event3Kind kind;
  std::uint32_t feature;
};

inline Nearest nearest_on_polygon(const std::vector<Vec3>& c, Vec3 q) {
  const std::size_t n = c.size();
  const Vec3 nrm = sim::cross(c[1] - c[0], c[2] - c[0]);
  const Vec3 un = (1.0 / sim::norm(nrm)) * nrm;
  bool inside = true;
  for (std::size_t k = 0; k < n; ++k)
    if (sim::dot(sim::cross(c[(k + 1) % n] - c[k], q - c[k]), un) < 0.0) inside = false;
  if (inside) {
    const double s = sim::dot(q - c[0], un);
    return {std::abs(s), q - s * un, sim::Event3Kind::ball_wall, 0};
  }
  Nearest best{1e300, {}, sim::Event3Kind::ball_wall_edge, 0};
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 e = c[(k + 1) % n] - c[k];
    const double s = std::clamp(sim::dot(q - c[k], e) / sim::norm2(e), 0.0, 1.0);
    const Vec3 p = c[k] + s * e;
    const double d = sim::norm(q - p);
    if (d < best.dist) {
      const bool end0 = s == 0.0, end1 = s == 1.0;
      best = {d, p, end0 || end1 ? sim::Event3Kind::ball_wall_corner : sim::Event3Kind::ball_wall_edge,
              static_cast<std::uint32_t>(end1 ? (k + 1) % n : k)};
    }
  }
  return best;
}

struct Reference3 {
  struct Ball { Vec3 x, v, a; double r, m, e, last; Vec3 omega; };
  std::vector<Ball> balls;
  std::vector<std::vector<Vec3>> walls;
  std::vector<double> wall_e;
  std::vector<std::vector<sim::Wall3Key>> wall_keys;
  double tc = 0.0;
  double t = 0.0;

  explicit Reference3(const sim::World3Def& def) : tc(def.tc) {
    for (const auto& s : def.spheres)
      balls.push_back({s.pos, s.vel, def.gravity + (s.charge / s.mass) * def.electric, s.radius, s.mass,
                       s.restitution, -1e300, (s.charge / s.mass) * def.magnetic});
    for (const auto& w : def.walls) {
      walls.push_back(w.corners);
      wall_e.push_back(w.restitution);
      wall_keys.push_back(w.keys);
    }
  }

  // Wall k's velocity and shift at t: the chord between the keys around t (at a key, the next).
  Vec3 wall_u(std::size_t k) const {
    const auto& keys = wall_keys[k];
    double t0 = 0.0;
    Vec3 s0;
    for (const sim::Wall3Key& key : keys) {
      if (key.t > t) return (1.0 / (key.t - t0)) * (key.shift - s0);
      t0 = key.t;
      s0 = key.shift;
    }
    return {};
  }
  Vec3 wall_shift(std::size_t k) const {
    const auto& keys = wall_keys[k];
    double t0 = 0.0;
    Vec3 s0;
    for (const sim::Wall3Key& key : keys) {
      if (key.t > t) return s0 + ((t - t0) / (key.t - t0)) * (key.shift - s0);
      t0 = key.t;
      s0 = key.shift;
    }
    return s0;
  }
  double next_key() const {
    double next = 1e300;
    for (const auto& keys : wall_keys)
      for (const sim::Wall3Key& key : keys)
        if (key.t > t) next = std::min(next, key.t);
    return next;
  }

  double e_of(const Ball& b) const { return t - b.last < tc ? 1.0 : b.e; }

  // The time a gap g can certainly not close in, at relative speed w and acceleration b.
  static double safe(double g, double w, double b) {
    return 2.0 * g / (w + std::sqrt(w * w + 2.0 * b * g));
  }

  // A magnetic field turns a charged ball's flight into a helix (sim::Helix3, checked against its
  // closed form in world3d_magnetic_test); |x''| bounds how fast its gaps can bend.
  static bool gyrates(const Ball& b) { return !(b.omega == Vec3{}); }
  static double accel_of(const Ball& b) {
    return gyrates(b) ? sim::Helix3(b.v, b.a, b.omega).accel() : sim::norm(b.a);
  }
  void fly_all(double dt) {
    for (Ball& b : balls) {
      if (gyrates(b)) {
        const sim::Helix3 h(b.v, b.a, b.omega);
        b.x = b.x + h.displacement(dt);
        b.v = h.velocity(dt);
        continue;
      }
      b.x = b.x + dt * b.v + (0.5 * dt * dt) * b.a;
      b.v = b.v + dt * b.a;
    }
  }

  /// Runs to t_end, appending events (ball_ball a < b; walls as the engine names them).
  void run(double t_end, std::vector<sim::Event3>& out, std::size_t max_events) {
    for (long steps = 0; steps < 50'000'000 && t < t_end && out.size() < max_events; ++steps) {
      const double key = next_key();
      double step = std::min(t_end, key) - t;
      bool served = false;
      for (std::size_t i = 0; i < balls.size() && !served; ++i) {
        for (std::size_t j = i + 1; j < balls.size() && !served; ++j) {
          const Vec3 d = balls[j].x - balls[i].x, w = balls[j].v - balls[i].v;
          const double g = sim::norm(d) - balls[i].r - balls[j].r;
          const double closing = -sim::dot(d, w) / sim::norm(d);
          const double b = gyrates(balls[i]) || gyrates(balls[j]) ? accel_of(balls[i]) + accel_of(balls[j])
                                                                   : sim::norm(balls[j].a - balls[i].a);
          if (g < 1e-12 * balls[i].r && closing > 0.0) {
            const Vec3 nn = (1.0 / sim::norm(d)) * d;
            const double mu = balls[i].m * balls[j].m / (balls[i].m + balls[j].m);
            const double s_in = -sim::dot(w, nn), e = std::max(e_of(balls[i]), e_of(balls[j]));
            const double s_out = e == 1.0 ? s_in : std::max(e * s_in, 0x1p-40 * sim::norm(w));
            const double jn = -mu * (s_in + s_out);
            balls[i].last = balls[j].last = t;
            balls[i].v = balls[i].v + (jn / balls[i].m) * nn;
            balls[j].v = balls[j].v - (jn / balls[j].m) * nn;
            out.push_back({t, sim::Event3Kind::ball_ball, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j), 0});
            served = true;
          } else if (closing > 0.0 || b > 0.0) {
            step = std::min(step, g < 1e-9 * balls[i].r && closing <= 0.0 ? -closing / b : safe(g, sim::norm(w), b));
          }
        }
        for (std::size_t k = 0; k < walls.size() && !served; ++k) {
          const Vec3 u = wall_u(k), q = balls[i].x - wall_shift(k), rel = balls[i].v - u;
          const Nearest nw = nearest_on_polygon(walls[k], q);
          const Vec3 d = q - nw.point;
          const double g = nw.dist - balls[i].r;
          const double closing = -sim::dot(d, rel) / nw.dist;
          const double b = accel_of(balls[i]);
          if (g < 1e-12 * balls[i].r && closing > 0.0) {
            const Vec3 nn = (1.0 / nw.dist) * d;
            const double e = balls[i].e * wall_e[k], s_in = -sim::dot(rel, nn);
            double s_out = s_in;
            if (e != 1.0) {
              s_out = std::max(e * s_in, 0x1p-40 * sim::norm(rel));
              if (sim::dot(balls[i].a, nn) < 0.0) s_out = std::max(s_out, -sim::dot(balls[i].a, nn) * tc / 2.0);
            }
            balls[i].v = balls[i].v + (s_in + s_out) * nn;
            balls[i].last = t;
            out.push_back({t, nw.kind, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(k), nw.feature});
            served = true;
          } else if (closing > 0.0 || b > 0.0) {
            step = std::min(step, g < 1e-9 * balls[i].r && closing <= 0.0 ? -closing / b : safe(g, sim::norm(rel), b));
          }
        }
      }
      if (served) continue;
      step = std::max(step, 1e-300);
      fly_all(std::min(step, t_end - t));
      t = std::min(t + step, t_end);
      if (t >= key) t = key;  // a key is reached exactly: the walls turn there
    }
  }
};

/// 8 spheres or so in a closed box of six polygons of our own (so the reference sees them), with a
/// slanted triangle and a slanted quad; gravity and an electric field on random charges optional.
inline sim::World3Def random_scene(std::uint64_t seed, int n, bool gravity, bool electric = false, bool magnetic = false) {
  std::mt19937_64 gen(seed);
  auto u = [&](double lo, double hi) { return lo + (hi - lo) * static_cast<double>(gen() >> 11) * 0x1.0p-53; };
  sim::World3Def def;
  def.size = {12, 12, 12};
  def.boundary = sim::Boundary3::none;
  if (gravity) def.gravity = {0.3, -0.5, -2.0};
  if (electric) def.electric = {0.8, 1.5, -1.0};
  if (magnetic) def.magnetic = {0.6, -0.9, 1.2};
  // A closed box of our own walls (so the reference sees them too), and two slanted polygons.
  const double L = 12;
  def.walls.push_back({{{0, 0, 0}, {0, L, 0}, {0, L, L}, {0, 0, L}}});
  def.walls.push_back({{{L, 0, 0}, {L, 0, L}, {L, L, L}, {L, L, 0}}});
  def.walls.push_back({{{0, 0, 0}, {0, 0, L}, {L, 0, L}, {L, 0, 0}}});
  def.walls.push_back({{{0, L, 0}, {L, L, 0}, {L, L, L}, {0, L, L}}});
  def.walls.push_back({{{0, 0, 0}, {L, 0, 0}, {L, L, 0}, {0, L, 0}}});
  def.walls.push_back({{{0, 0, L}, {0, L, L}, {L, L, L}, {L, 0, L}}});
  def.walls.push_back({{{3, 3, 4}, {8, 4, 5}, {5, 8, 6}}});
  def.walls.push_back({{{7, 6, 8}, {10, 6, 9}, {10, 9, 9}, {7, 9, 8}}});
  while (static_cast<int>(def.spheres.size()) < n) {
    const double r = u(0.4, 0.8);
    const Vec3 x{u(1, 11), u(1, 11), u(1, 11)};
    bool ok = true;
    for (const auto& s : def.spheres) ok = ok && sim::norm(s.pos - x) > s.radius + r + 0.05;
    for (const auto& wd : def.walls) ok = ok && nearest_on_polygon(wd.corners, x).dist > r + 0.05;
    if (ok) def.spheres.push_back({x, {u(-2, 2), u(-2, 2), u(-2, 2)}, r, u(0.5, 2.0), electric || magnetic ? u(-1.5, 1.5) : 0.0});
  }
  return def;
}

/// Runs def to `until` in the engine and in the reference and requires the two to agree event
/// for event (kind, bodies, wall feature, time within 1e-7) over the first 40 events at most, at
/// least 15: hard spheres are chaotic, and the reference's 1e-12 r contact tolerance grows by the
/// ratio of free path to radius at each collision. Counts the compared events by kind into `kinds`
/// (indexed by Event3Kind) and returns them (the engine's) with the engine's overlap at the end.
struct Agreed {
  std::vector<sim::Event3> events;
  double overlap = 0.0;  ///< World3::max_overlap_now at `until`
};
inline Agreed agree_with_reference(const sim::World3Def& def, double until, int (&kinds)[6]) {
  sim::World3 w(def);
  std::vector<sim::Event3> fast, slow;
  w.advance_to(until, &fast);
  Reference3 ref(def);
  ref.run(until, slow, fast.size() + 1);
  const std::size_t n = std::min<std::size_t>(std::min(fast.size(), slow.size()), 40);
  REQUIRE(n >= 15);
  for (std::size_t k = 0; k < n; ++k) {
    INFO("event " << k << " t " << fast[k].t << " vs " << slow[k].t);
    REQUIRE(fast[k].kind == slow[k].kind);
    ++kinds[static_cast<int>(fast[k].kind)];
    const auto lo = std::min(fast[k].a, fast[k].b), hi = std::max(fast[k].a, fast[k].b);
    if (fast[k].kind == sim::Event3Kind::ball_ball) {
      REQUIRE(lo == slow[k].a);
      REQUIRE(hi == slow[k].b);
    } else {
      REQUIRE(fast[k].a == slow[k].a);
      REQUIRE(fast[k].b == slow[k].b);
      REQUIRE(fast[k].c == slow[k].c);
    }
    REQUIRE(std::abs(fast[k].t - slow[k].t) < 1e-7);
  }
  fast.resize(n);
  return {fast, w.max_overlap_now()};
}

}  // namespace turtlegas::test3
