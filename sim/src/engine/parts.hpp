// SPDX-License-Identifier: MIT
// What the rooms see of each other. The interactions and the neighbourhood scans do not reach
// into the engine: a prediction receives a Look (everything it reads, all const), an event's
// response receives Parts (the rooms it changes, by reference). Both are built by the engine for
// each call and cost nothing once inlined. Here too are the small rooms that only they share: the
// restitution law, step mode's path lengths, and the record of what happened.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "arena.hpp"
#include "body_store.hpp"
#include "flights.hpp"
#include "moving_walls.hpp"
#include "turtle_motion.hpp"
#include "turtlegas/sim/events.hpp"
#include "turtlegas/sim/world.hpp"
#include "walls.hpp"

namespace turtlegas::sim::detail {

/// The length of a straight path at speed |v| for dt.
inline double path_length(Vec2 v, double dt) { return norm(v) * dt; }

/// The memo's restitution ("2 replaced by 1 + e"), with the TC rule and the rest threshold.
struct Restitution {
  double e = 1.0;
  double tc = 0.0;
  bool inelastic = false;
  std::vector<double> last_time;  ///< per body, when it last changed course (only when e < 1)

  /// The TC rule (Luding & McNamara): a ball that collided less than tc ago collides elastically,
  /// so a cluster cannot collapse into infinitely many collisions in finite time.
  double for_ball(std::uint32_t i, double now) const { return now - last_time[i] < tc ? 1.0 : e; }
  double for_pair(std::uint32_t i, std::uint32_t j, double now) const {
    double out = e;
    if (inelastic) out = std::max(for_ball(i, now), for_ball(j, now));
    return out;
  }
  /// A ball's velocity v relative to an obstacle after bouncing off it; n is the unit contact
  /// normal pointing from the obstacle to the ball, a_n the field's acceleration of the ball along
  /// it, a_rest the same for the ball at rest (a_n without the magnetic part). Walls take the
  /// plain restitution: the TC rule is for ball clusters; a ball pressed onto a wall is kept from
  /// collapsing by the rest threshold.
  Vec2 bounce(Vec2 v, Vec2 n, double a_n, double a_rest) const {
    const double w = -dot(v, n);
    double w_out = e * w;
    // The rest threshold: a ball pressed onto the obstacle by the field leaves it at least fast
    // enough to stay away for tc. Without it an inelastic ball would bounce infinitely often before
    // coming to rest, and a ball at rest would sink.
    if (a_n < 0.0) {
      const double floor = -a_n * tc / 2.0;
      if (w_out < floor) {
        // An elastic bounce keeps the ball's energy: the normal speed the threshold asks for is
        // taken from the tangential speed (v turned, |v| kept) whenever |v| has that much. Only a
        // ball slower than the threshold is lifted with energy (a ball at rest would sink). Under
        // a strong field (q/m = 1e6 in E: floor ~ 10) adding it at every skipping bounce made
        // energy grow without bound.
        if (e == 1.0) return elastic_floor(v, n, w, floor, a_rest);
        w_out = floor;
      }
    }
    return v + (w + w_out) * n;
  }
  /// The elastic bounce below the threshold (bounce()): out of line, off the common path.
  [[gnu::cold]] Vec2 elastic_floor(Vec2 v, Vec2 n, double w, double floor, double a_rest) const {
    const Vec2 vt = v + w * n;  // the tangential part
    const double speed2 = dot(v, v), floor2 = floor * floor, vt2 = dot(vt, vt);
    if (speed2 > floor2 && vt2 > 0.0) return floor * n + std::sqrt((speed2 - floor2) / vt2) * vt;
    // Slower than the threshold, but faster than the threshold of a ball at rest (the pull
    // without its magnetic part, which a resting ball does not feel): all of its speed
    // along the normal, still without adding energy. Under a strong B the pull includes
    // W n.J(v), which grows with the speed itself (|W| tc / 2 = 1 at W = 2e4 asks for a
    // normal speed of |v_t|), and fast balls skipping along a wall were lifted with energy
    // (a mixed gas at q/m 1e6, Bz 0.01, gained 6e-5 of its energy in 200 events). Such a
    // ball leaves at least as fast as the resting threshold asks, so it stays away for about tc
    // against the rest of the pull, and B alone brings it back after about half a turn.
    const double rest_floor = -std::min(a_rest, 0.0) * tc / 2.0;
    if (speed2 > rest_floor * rest_floor) return std::sqrt(speed2) * n;
    return v + (w + floor) * n;
  }
};

/// Step mode's bookkeeping of one step: how far bodies have gone, and the marks that keep a ring
/// scan from looking at a wall twice.
struct StepState {
  std::uint64_t index = 0;      ///< steps done
  double rmax = 0.0;            ///< the largest radius
  double dmax = 0.0;            ///< the largest path length of any body in this step
  std::vector<double> travel;   ///< per body: path length so far in this step
  std::vector<std::uint32_t> stamp;  ///< de-duplicates walls and ends in ring scans
  std::uint32_t scan = 0;
};

/// What the engine reports: its counts, the deepest contact seen, and the event log.
struct EventRecord {
  Stats stats;
  Overlap max_contact;
  std::vector<Event>* log = nullptr;
  std::vector<Impulse>* impulses = nullptr;  ///< World::set_impulse_log

  void note_contact(double depth, double radius) {
    if (depth > max_contact.depth) max_contact.depth = depth;
    if (depth / radius > max_contact.relative) max_contact.relative = depth / radius;
  }
  void note(double t, EventKind kind, std::uint32_t a, std::uint32_t b, std::uint32_t c = 0, std::uint8_t flags = 0) {
    if (log) log->push_back({t, kind, a, b, c, flags});
  }
};

/// What a prediction reads.
template <Flight F, bool kExtras>
struct Look {
  const BodyStore& bodies;
  const Walls& walls;
  const WallSchedule& schedule;
  const Motion<F, kExtras>& motion;
  double now;

  bool is_turtle(std::uint32_t id) const { return motion.is_turtle(id); }
  /// Collision layers: whether two bodies, or a body and a wall or wall end, can touch at all.
  bool meets(std::uint32_t i, std::uint32_t j) const {
    // Bodies' layers are fixed at construction; when all are the defaults (which meet), the pair
    // test reads neither (with many turtles layers[j] is a cache miss per candidate).
    if constexpr (kExtras) return !bodies.layered || bodies.layers[i].collides_with(bodies.layers[j]);
    else return true;
  }
  bool meets_wall(std::uint32_t i, std::uint32_t w) const {
    if constexpr (kExtras) return bodies.layers[i].collides_with(walls.layers[w]);
    else return true;
  }
  bool meets_end(std::uint32_t i, std::uint32_t e) const {
    if constexpr (kExtras) return bodies.layers[i].collides_with(walls.end_layers[e]);
    else return true;
  }
};

/// Brings body i to internal time `now` along its flight (step mode also adds up its path).
template <Flight F, bool kStep, bool kExtras>
void sync_body(BodyStore& bodies, const Motion<F, kExtras>& motion, StepState& step, std::uint32_t i, double now) {
  Body& b = bodies.body[i];
  const double dt = now - b.t;
  if constexpr (kStep) step.travel[i] += path_length(b.v, dt);
  const FieldState s = motion.state(b, i, dt);
  b.x = s.x;
  b.v = s.v;
  b.t = now;
}

/// What an event's response changes, and the clock's reading.
template <Flight F, bool kStep, bool kExtras>
struct Parts {
  BodyStore& bodies;
  const Motion<F, kExtras>& motion;
  Walls& walls;
  WallSchedule& schedule;
  Turtles& turtles;
  const Arena& arena;
  Restitution& restitution;
  StepState& step;
  EventRecord& record;
  double now;     ///< internal time
  double t_base;  ///< external time of internal zero
  double dt;      ///< the step (step mode), and the control step turtles coast to

  bool is_turtle(std::uint32_t id) const { return motion.is_turtle(id); }
  void sync(std::uint32_t i) const { sync_body<F, kStep, kExtras>(bodies, motion, step, i, now); }
  void note(EventKind kind, std::uint32_t a, std::uint32_t b) const { record.note(t_base + now, kind, a, b); }
  /// Ball a received dp in a collision with b (World::set_impulse_log); r as Impulse::r.
  void impulse(EventKind kind, std::uint32_t a, std::uint32_t b, Vec2 dp, Vec2 r) const {
    record.impulses->push_back({t_base + now, kind, a, b, dp, r});
  }
  /// Body i changed course: predictions made with it are stale.
  void changed(std::uint32_t i) const {
    ++bodies.body[i].count;
    if (restitution.inelastic) restitution.last_time[i] = now;
    if constexpr (kStep) {
      // The rest of the step is walked at the new speed.
      step.dmax = std::max(step.dmax, step.travel[i] + path_length(bodies.body[i].v, dt - now));
    }
  }
  /// Body `id`, a turtle, touched `other` (see Turtles::touch).
  void touch(std::uint32_t id, EventKind kind, std::uint32_t other, Vec2 normal) const {
    turtles.touch(id - bodies.balls(), bodies.body[id], bodies.end[id], now, t_base, dt, kind, other, normal);
  }
  /// Whether turtle `id` is carried (Turtles::pushed_by): by a translating moving wall, or by a
  /// turtle so carried, that still touches it and still pushes it; then `v` is the velocity it is
  /// carried at (the pusher's normal speed, along the normal). Such a turtle cannot stop dead at a
  /// touch as a driving one does: what pushes it has infinite mass (docs/physics.md, "Wedged and
  /// crushed bodies").
  bool carried(std::uint32_t id, Vec2& v, std::size_t depth = 0) const {
    const std::uint32_t nb = bodies.balls();
    const std::size_t k = id - nb;
    if (id < nb || k >= turtles.pushed_by.size() || turtles.pushed_by[k] == kNone || depth > turtles.size()) return false;
    const Body& b = bodies.body[id];
    const Vec2 x = b.x + (now - b.t) * b.v;  // (a turtle flies straight)
    Vec2 n, u;
    double gap = 0.0;
    if (const std::uint32_t via = turtles.pushed_via[k]; via == kNone) {
      const Mover& m = schedule.movers[turtles.pushed_by[k]];
      if (!m.rigid()) return false;  // a turning wall knocks a turtle off instead (apply_wall)
      const Segment s = m.segment_at(walls.segments[m.wall], now);
      const Vec2 rel = arena.rel_to_segment(x, s);
      const Vec2 off = rel - std::clamp(dot(rel, s.u), 0.0, s.len) * s.u;
      const double dist = norm(off);
      if (!(dist > 0.0)) return false;
      n = off / dist;
      gap = dist - b.r;
      u = m.u;
    } else {
      const std::uint32_t j = nb + via;
      if (!carried(j, u, depth + 1)) return false;
      const Body& bj = bodies.body[j];
      const Vec2 d = arena.min_image(x - (bj.x + (now - bj.t) * bj.v));
      const double dist = norm(d);
      if (!(dist > 0.0)) return false;
      n = d / dist;
      gap = dist - b.r - bj.r;
    }
    // Touching: within the overlap budget (and the round-off of positions far from the origin).
    const double un = dot(u, n);
    if (!(gap <= 1e-9 * b.r + 0x1p-46 * (std::abs(x.x) + std::abs(x.y))) || !(un > 0.0)) return false;
    v = un * n;
    return true;
  }
  /// The bounce of ball i (at the contact, its velocity not yet changed) off an obstacle, v its
  /// velocity relative to the obstacle (Restitution::bounce, under the ball's field, plus `press`:
  /// the ball's acceleration along n relative to the obstacle that the obstacle's own motion adds,
  /// a turning wall's; negative presses).
  Vec2 bounce(std::uint32_t i, Vec2 v, Vec2 n, double press = 0.0) const {
    const double a_n = motion.flight().normal_accel(i, bodies.body[i].v, n) + press;
    // A ball at rest feels no magnetic part (only the charged flight has one).
    if constexpr (F::kBoundedHorizon) return restitution.bounce(v, n, a_n, motion.flight().normal_accel(i, Vec2{}, n) + press);
    else return restitution.bounce(v, n, a_n, a_n);
  }
};

}  // namespace turtlegas::sim::detail
