// SPDX-License-Identifier: MIT
#include "turtlegas/sim/reference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "turtlegas/sim/field_flight.hpp"
#include "turtlegas/sim/field_toi.hpp"

namespace turtlegas::sim::reference {

namespace {

/// A wall end met by a ball: its point, the first wall ending there, and the layers of every wall
/// ending there (an end is there for a ball if any of them is).
struct End {
  Vec2 p;
  std::uint32_t wall;
  Layers layers{0u, 0u};
};

/// The scene's walls, the arena's after them, as segments, and their ends, each point once.
struct Walls {
  std::vector<WallDef> defs;
  std::vector<Segment> segments;
  std::vector<End> ends;
};

Walls walls_of(const WorldDef& def) {
  Walls out;
  out.defs = def.walls;
  if (def.arena.boundary == Boundary::walls)
    for (auto& w : arena_walls(def.arena)) out.defs.push_back(w);
  out.segments.reserve(out.defs.size());
  for (const auto& w : out.defs) out.segments.push_back(make_segment(w.from, w.to));
  for (std::uint32_t w = 0; w < out.defs.size(); ++w)
    for (Vec2 p : {out.defs[w].from, out.defs[w].to}) {
      End* seen = nullptr;
      for (End& x : out.ends)
        if (x.p == p) seen = &x;
      if (!seen) {
        out.ends.push_back({p, w});
        seen = &out.ends.back();
      }
      seen->layers.category |= out.defs[w].layers.category;
      seen->layers.mask |= out.defs[w].layers.mask;
    }
  return out;
}

}  // namespace

std::vector<Event> events(const WorldDef& def, double t_end, std::vector<BallState>* final) {
  if (def.arena.boundary == Boundary::periodic)
    throw std::invalid_argument("reference::events supports boundaries none and walls only");
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  enum Kind : std::uint32_t { kBall = 1, kWall = 2, kEnd = 3 };
  const Vec2 g = def.effects.gravity;
  const bool accel = g.x != 0.0 || g.y != 0.0;
  const double e = def.effects.restitution, tc = def.effects.tc;
  const bool inelastic = e < 1.0;

  const Walls all = walls_of(def);
  const std::vector<WallDef>& wall_defs = all.defs;
  const std::vector<Segment>& walls = all.segments;
  const std::vector<End>& ends = all.ends;

  const std::size_t n = def.balls.size();
  std::vector<Vec2> x(n), v(n);
  std::vector<bool> alive(n, true);
  std::vector<std::uint32_t> last(n, kNone);
  std::vector<double> last_time(n, -kNever);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = def.balls[i].pos;
    v[i] = def.balls[i].vel;
  }
  auto code = [](std::uint32_t kind, std::size_t index) { return (kind << 30) | static_cast<std::uint32_t>(index); };
  auto e_for = [&](std::size_t i, double now) { return now - last_time[i] < tc ? 1.0 : e; };

  std::vector<Event> out;
  double now = 0.0;
  for (;;) {
    double best = kNever;
    std::uint32_t kind = 0;
    std::size_t bi = 0, bj = 0;
    auto offer = [&](double dt, std::uint32_t k, std::size_t i, std::size_t j) {
      if (now + dt < best) {
        best = now + dt;
        kind = k;
        bi = i;
        bj = j;
      }
    };
    for (std::size_t i = 0; i < n; ++i) {
      if (!alive[i]) continue;
      const double r = def.balls[i].radius;
      if (def.effects.ball_ball)
        for (std::size_t j = i + 1; j < n; ++j) {
          if (!alive[j]) continue;
          if (last[i] == code(kBall, j) && last[j] == code(kBall, i)) continue;
          if (!def.balls[i].layers.collides_with(def.balls[j].layers)) continue;
          offer(toi_disc_disc(x[j] - x[i], v[j] - v[i], r + def.balls[j].radius), kBall, i, j);
        }
      for (std::size_t w = 0; w < walls.size(); ++w) {
        if (!accel && last[i] == code(kWall, w)) continue;
        if (!def.balls[i].layers.collides_with(wall_defs[w].layers)) continue;
        offer(toi_disc_segment(x[i] - walls[w].p1, v[i], g, walls[w], r), kWall, i, w);
      }
      for (std::size_t k = 0; k < ends.size(); ++k) {
        if (!accel && last[i] == code(kEnd, k)) continue;
        if (!def.balls[i].layers.collides_with(ends[k].layers)) continue;
        offer(toi_disc_point_accel(x[i] - ends[k].p, v[i], g, r, best - now), kEnd, i, k);
      }
      if (def.arena.boundary == Boundary::none) {
        const AxisExit ex = axis_exit(x[i].x, v[i].x, g.x, 0.0, def.arena.width);
        const AxisExit ey = axis_exit(x[i].y, v[i].y, g.y, 0.0, def.arena.height);
        offer(std::min(ex.t, ey.t), 0, i, 0);
      }
    }
    const double t_next = std::min(best, t_end);
    for (std::size_t i = 0; i < n; ++i) {
      if (!alive[i]) continue;
      const double dt = t_next - now;
      x[i] = x[i] + dt * v[i] + (0.5 * dt * dt) * g;
      v[i] = v[i] + dt * g;
    }
    now = t_next;
    if (best > t_end) break;
    auto bounce = [&](std::size_t i, Vec2 vel, Vec2 nrm) {
      const double w = -dot(vel, nrm);
      (void)i;
      double w_out = e * w;
      const double a_n = dot(g, nrm);
      if (accel && a_n < 0.0) w_out = std::max(w_out, -a_n * tc / 2.0);
      return vel + (w + w_out) * nrm;
    };
    if (kind == kBall) {
      const double ee = inelastic ? std::max(e_for(bi, now), e_for(bj, now)) : e;
      respond_disc_disc(v[bi], v[bj], def.balls[bi].mass, def.balls[bj].mass, x[bj] - x[bi], ee);
      out.push_back({now, EventKind::ball_ball, static_cast<std::uint32_t>(bi), static_cast<std::uint32_t>(bj)});
      last[bi] = code(kBall, bj);
      last[bj] = code(kBall, bi);
      last_time[bi] = last_time[bj] = now;
    } else if (kind == kWall) {
      const Segment& s = walls[bj];
      const double d = dot(x[bi] - s.p1, s.n);
      v[bi] = bounce(bi, v[bi], d >= 0.0 ? s.n : -s.n);
      out.push_back({now, EventKind::ball_wall, static_cast<std::uint32_t>(bi), static_cast<std::uint32_t>(bj)});
      last[bi] = code(kWall, bj);
      last_time[bi] = now;
    } else if (kind == kEnd) {
      const Vec2 F = x[bi] - ends[bj].p;
      v[bi] = bounce(bi, v[bi], F / norm(F));
      out.push_back({now, EventKind::ball_wall_end, static_cast<std::uint32_t>(bi), ends[bj].wall});
      last[bi] = code(kEnd, bj);
      last_time[bi] = now;
    } else {
      alive[bi] = false;
      out.push_back({now, EventKind::exit, static_cast<std::uint32_t>(bi), 0});
    }
  }
  if (final) {
    final->resize(n);
    for (std::size_t i = 0; i < n; ++i) (*final)[i] = {x[i], v[i], alive[i]};
  }
  return out;
}

BallState ballistic(const BallDef& ball, const ArenaDef& arena, double g, double t) {
  const double r = ball.radius;
  const Vec2 x0 = ball.pos;
  const Vec2 v0 = ball.vel;
  const double h = x0.y - r;  // height of the centre above its floor contact
  if (!(g > 0.0)) throw std::invalid_argument("ballistic: g must be > 0");
  if (!(x0.x >= r && x0.x <= arena.width - r && h >= 0.0 && x0.y <= arena.height - r))
    throw std::invalid_argument("ballistic: the ball must start inside the arena, at least a radius from each edge");
  // Speed at the floor, the same at every bounce (elastic).
  const double impact = std::sqrt(v0.y * v0.y + 2.0 * g * h);
  if (!(impact > 0.0)) throw std::invalid_argument("ballistic: a ball at rest on the floor has no bouncing trajectory");
  if (!(r + impact * impact / (2.0 * g) < arena.height - r))
    throw std::invalid_argument("ballistic: the ball's apex reaches the ceiling; lower it or slow it down");

  // x: the free line unfolded into a circle of circumference 2L; the second half runs back.
  const double span = arena.width - 2.0 * r;
  double u = std::fmod((x0.x - r) + v0.x * t, 2.0 * span);
  if (u < 0.0) u += 2.0 * span;
  const bool back = u > span;
  const double x = r + (back ? 2.0 * span - u : u);
  const double vx = back ? -v0.x : v0.x;

  // y: the first landing is the larger root of h + v0.y s - g s^2 / 2 = 0; for a ball thrown down
  // it is written as 2h / (impact - v0.y), whose terms add, so a ball just above the floor keeps
  // its digits. After it every flight is the same parabola, of period 2 impact / g.
  const double land = v0.y > 0.0 ? (v0.y + impact) / g : 2.0 * h / (impact - v0.y);
  if (t < land) return {{x, x0.y + t * (v0.y - 0.5 * g * t)}, {vx, v0.y - g * t}, true};
  const double period = 2.0 * impact / g;
  const double s = std::fmod(t - land, period);
  return {{x, r + s * (impact - 0.5 * g * s)}, {vx, impact - g * s}, true};
}

std::vector<Event> field_events(const WorldDef& def, double t_end, std::vector<BallState>* final) {
  if (def.arena.boundary == Boundary::periodic)
    throw std::invalid_argument("reference::field_events supports boundaries none and walls only");
  const Walls all = walls_of(def);
  const std::vector<Segment>& walls = all.segments;
  const std::vector<End>& ends = all.ends;
  const std::size_t n = def.balls.size();
  const EffectsDef& fx = def.effects;
  std::vector<FieldFlight> f(n);
  std::vector<Vec2> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    const BallDef& b = def.balls[i];
    const double qm = b.charge / b.mass;
    f[i] = {b.vel, fx.gravity + qm * fx.electric, qm * fx.magnetic};
    x[i] = b.pos;
  }
  std::vector<Event> out;
  double now = 0.0;
  for (;;) {
    double best = t_end - now;
    int kind = 0;
    std::size_t bi = 0, bj = 0;
    auto offer = [&](double dt, int k, std::size_t i, std::size_t j) {
      if (dt < best) {
        best = dt;
        kind = k;
        bi = i;
        bj = j;
      }
    };
    for (std::size_t i = 0; i < n; ++i) {
      const double r = def.balls[i].radius;
      for (std::size_t j = i + 1; j < n; ++j)
        offer(toi_field_disc_disc(x[j] - x[i], f[i], f[j], r + def.balls[j].radius, best), 1, i, j);
      for (std::size_t w = 0; w < walls.size(); ++w)
        offer(toi_field_disc_segment(x[i] - walls[w].p1, f[i], walls[w], r, best), 2, i, w);
      for (std::size_t k = 0; k < ends.size(); ++k) offer(toi_field_disc_point(x[i] - ends[k].p, f[i], r, best), 3, i, k);
    }
    for (std::size_t i = 0; i < n; ++i) {
      const FieldState s = field_advance(x[i], f[i], best);
      x[i] = s.x;
      f[i].v = s.v;
    }
    now += best;
    if (kind == 0) break;
    if (kind == 1) {
      respond_disc_disc(f[bi].v, f[bj].v, def.balls[bi].mass, def.balls[bj].mass, x[bj] - x[bi], 1.0);
      out.push_back({now, EventKind::ball_ball, static_cast<std::uint32_t>(bi), static_cast<std::uint32_t>(bj)});
    } else if (kind == 2) {
      const Segment& s = walls[bj];
      const Vec2 nrm = dot(x[bi] - s.p1, s.n) >= 0.0 ? s.n : -s.n;
      f[bi].v -= 2.0 * dot(f[bi].v, nrm) * nrm;
      out.push_back({now, EventKind::ball_wall, static_cast<std::uint32_t>(bi), static_cast<std::uint32_t>(bj)});
    } else {
      const Vec2 F = x[bi] - ends[bj].p;
      const Vec2 nrm = F / norm(F);
      f[bi].v -= 2.0 * dot(f[bi].v, nrm) * nrm;
      out.push_back({now, EventKind::ball_wall_end, static_cast<std::uint32_t>(bi), ends[bj].wall});
    }
  }
  if (final) {
    final->clear();
    for (std::size_t i = 0; i < n; ++i) final->push_back({x[i], f[i].v, true});
  }
  return out;
}

}  // namespace turtlegas::sim::reference
