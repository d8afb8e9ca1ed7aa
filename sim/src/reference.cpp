// SPDX-License-Identifier: MIT
#include "turtlegas/sim/reference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace turtlegas::sim::reference {
namespace {

Vec2 min_image(Vec2 d, double w, double h) {
  if (w > 0.0) d.x -= w * std::round(d.x / w);
  if (h > 0.0) d.y -= h * std::round(d.y / h);
  return d;
}

double distance_to_segment(Vec2 p, const Segment& s) {
  const Vec2 rel = p - s.p1;
  const double foot = std::clamp(dot(rel, s.u), 0.0, s.len);
  return norm(rel - foot * s.u);
}

}  // namespace

Overlap overlap(const DiscView& discs, const std::vector<Segment>& walls, double periodic_width, double periodic_height,
                bool ball_pairs, const std::vector<Layers>* body_layers, const std::vector<Layers>* wall_layers) {
  auto meet = [&](std::size_t i, std::size_t j) { return !body_layers || (*body_layers)[i].collides_with((*body_layers)[j]); };
  auto meet_wall = [&](std::size_t i, std::size_t w) {
    return !body_layers || !wall_layers || (*body_layers)[i].collides_with((*wall_layers)[w]);
  };
  Overlap worst;
  auto note = [&](double depth, double r) {
    if (depth <= 0.0) return;
    worst.depth = std::max(worst.depth, depth);
    worst.relative = std::max(worst.relative, depth / r);
  };
  const std::size_t n = discs.n;
  double rmax = 0.0;
  std::size_t live = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (discs.alive(i)) {
      rmax = std::max(rmax, discs.radius(i));
      ++live;
    }
  if (rmax == 0.0) return worst;

  for (std::size_t i = 0; i < n; ++i) {
    if (!discs.alive(i)) continue;
    const double r = discs.radius(i);
    for (std::size_t w = 0; w < walls.size(); ++w) {
      const Segment& s = walls[w];
      if (!meet_wall(i, w)) continue;
      Vec2 p = discs.pos(i);
      if (periodic_width > 0.0) p = s.p1 + min_image(p - s.p1, periodic_width, periodic_height);
      note(r - distance_to_segment(p, s), r);
    }
  }
  if (!ball_pairs) return worst;

  // Sort by cell of side 2 rmax and compare with the 3x3 neighbouring cells: an independent grid.
  // Only the disc indices are stored; cells are recomputed from positions when compared.
  const double cell = 2.0 * rmax;
  struct Cell {
    std::int64_t cx, cy;
    auto operator<=>(const Cell&) const = default;
  };
  auto cell_of = [&](std::size_t i) {
    Vec2 p = discs.pos(i);
    if (periodic_width > 0.0) p = {p.x - periodic_width * std::floor(p.x / periodic_width),
                                   p.y - periodic_height * std::floor(p.y / periodic_height)};
    return Cell{static_cast<std::int64_t>(std::floor(p.x / cell)), static_cast<std::int64_t>(std::floor(p.y / cell))};
  };
  std::vector<std::uint32_t> order;
  order.reserve(live);
  for (std::size_t i = 0; i < n; ++i)
    if (discs.alive(i)) order.push_back(static_cast<std::uint32_t>(i));
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const Cell ca = cell_of(a), cb = cell_of(b);
    return ca != cb ? ca < cb : a < b;
  });
  auto check_pair = [&](std::size_t i, std::size_t j) {
    if (!meet(i, j)) return;
    const Vec2 d = min_image(discs.pos(j) - discs.pos(i), periodic_width, periodic_height);
    const double ri = discs.radius(i), rj = discs.radius(j);
    note(ri + rj - norm(d), std::min(ri, rj));
  };
  const std::int64_t ncx = periodic_width > 0.0 ? static_cast<std::int64_t>(std::floor(periodic_width / cell)) : 0;
  const std::int64_t ncy = periodic_height > 0.0 ? static_cast<std::int64_t>(std::floor(periodic_height / cell)) : 0;
  const bool brute = periodic_width > 0.0 && (ncx < 3 || ncy < 3);
  if (brute || order.size() < 64) {
    for (std::size_t a = 0; a < order.size(); ++a)
      for (std::size_t b = a + 1; b < order.size(); ++b) check_pair(order[a], order[b]);
    return worst;
  }
  for (const std::uint32_t i : order) {
    const Cell home = cell_of(i);
    for (std::int64_t dy = -1; dy <= 1; ++dy)
      for (std::int64_t dx = -1; dx <= 1; ++dx) {
        Cell c{home.cx + dx, home.cy + dy};
        if (periodic_width > 0.0) {
          // Cells past the last whole one belong to the last; wrap the rest.
          c.cx = ((c.cx % (ncx + 1)) + (ncx + 1)) % (ncx + 1);
          c.cy = ((c.cy % (ncy + 1)) + (ncy + 1)) % (ncy + 1);
        }
        auto it = std::partition_point(order.begin(), order.end(), [&](std::uint32_t k) { return cell_of(k) < c; });
        for (; it != order.end() && cell_of(*it) == c; ++it)
          if (*it > i) check_pair(i, *it);
      }
  }
  return worst;
}

Overlap overlap(const std::vector<Vec2>& pos, const std::vector<double>& radius, const std::vector<bool>& alive,
                const std::vector<Segment>& walls, double periodic_width, double periodic_height, bool ball_pairs,
                const std::vector<Layers>* body_layers, const std::vector<Layers>* wall_layers) {
  const DiscView discs{pos.size(), [&](std::size_t i) { return pos[i]; }, [&](std::size_t i) { return radius[i]; },
                       [&](std::size_t i) { return static_cast<bool>(alive[i]); }};
  return overlap(discs, walls, periodic_width, periodic_height, ball_pairs, body_layers, wall_layers);
}

std::vector<Event> events(const WorldDef& def, double t_end, std::vector<BallState>* final) {
  if (def.arena.boundary == Boundary::periodic)
    throw std::invalid_argument("reference::events supports boundaries none and walls only");
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  enum Kind : std::uint32_t { kBall = 1, kWall = 2, kEnd = 3 };
  const Vec2 g = def.effects.gravity;
  const bool accel = g.x != 0.0 || g.y != 0.0;
  const double e = def.effects.restitution, tc = def.effects.tc;
  const bool inelastic = e < 1.0;

  std::vector<WallDef> wall_defs = def.walls;
  if (def.arena.boundary == Boundary::walls)
    for (auto& w : arena_walls(def.arena)) wall_defs.push_back(w);
  std::vector<Segment> walls;
  for (const auto& w : wall_defs) walls.push_back(make_segment(w.from, w.to));
  struct End {
    Vec2 p;
    std::uint32_t wall;
    Layers layers{0u, 0u};  // an end is there for a ball if any wall ending there is
  };
  std::vector<End> ends;
  for (std::uint32_t w = 0; w < wall_defs.size(); ++w)
    for (Vec2 p : {wall_defs[w].from, wall_defs[w].to}) {
      End* seen = nullptr;
      for (End& x : ends)
        if (x.p == p) seen = &x;
      if (!seen) {
        ends.push_back({p, w});
        seen = &ends.back();
      }
      seen->layers.category |= wall_defs[w].layers.category;
      seen->layers.mask |= wall_defs[w].layers.mask;
    }

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

}  // namespace turtlegas::sim::reference
