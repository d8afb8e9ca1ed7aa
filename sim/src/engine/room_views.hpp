// SPDX-License-Identifier: MIT
// What the rooms see of each other. The interactions and the neighbourhood scans do not reach
// into the engine: a prediction receives a Look (everything it reads, all const), an event's
// response receives Parts (the rooms it changes, by reference). Both are built by the engine for
// each call and cost nothing once inlined. Here too are the small rooms that only they share:
// step mode's path lengths and the record of what happened. (The restitution law they apply is
// the contacts room's: contacts/restitution.hpp.)
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "arena.hpp"
#include "body_store.hpp"
#include "contacts/restitution.hpp"
#include "flights.hpp"
#include "moving_walls.hpp"
#include "turtle_motion.hpp"
#include "turtlegas/sim/events.hpp"
#include "turtlegas/sim/world.hpp"
#include "walls.hpp"

namespace turtlegas::sim::detail {

/// The length of a straight path at speed |v| for dt.
inline double path_length(Vec2 v, double dt) { return norm(v) * dt; }

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
  /// Per ball: the energy the zero-time rules took from it (World::energy_taken).
  std::vector<double> taken;
  /// A zero-time rule took energy e from ball `ball`: into its rule's total (a Stats::energy_*).
  void take_energy(double& rule_total, std::uint32_t ball, double e) {
    rule_total += e;
    if (taken.size() <= ball) taken.resize(ball + 1, 0.0);
    taken[ball] += e;
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
  /// How far body i's searches look (internal time): t_coll, but no further than the end of its
  /// arc if it is a turtle on one (the searches on a circle need a finite horizon, and the arc's
  /// end predicts afresh).
  double horizon(std::uint32_t i, double t_coll) const {
    if (motion.any_arcs() && motion.arcs(i)) [[unlikely]] return std::min(t_coll, bodies.end[i]);
    return t_coll;
  }
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
  Motion<F, kExtras>& motion;
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
  /// An event of `kind` served between a and b (as the log names them): its Stats `counter`
  /// bumped and its line logged.
  [[gnu::always_inline]] void count(std::uint64_t& counter, EventKind kind, std::uint32_t a, std::uint32_t b) const {
    ++counter;
    note(kind, a, b);
  }
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
    const std::size_t k = id - bodies.balls();
    turtles.touch(k, bodies.body[id], bodies.end[id], now, t_base, dt, kind, other, normal);
    motion.set_arc(k, 0.0);  // stopped dead, or coasting straight after a bounce
    if (const std::uint64_t j = turtles.end_step[k]; j != kNoStep)
      bodies.end[id] = internal_boundary(j, t_base, dt, kStep, step.index);
  }
  /// The bounce of ball i (at the contact, its velocity not yet changed) off an obstacle, v its
  /// velocity relative to the obstacle (Restitution::bounce, under the ball's field, plus `press`:
  /// the ball's acceleration along n relative to the obstacle that the obstacle's own motion adds,
  /// a turning wall's; negative presses). `curve`: what the obstacle's own curvature adds to the
  /// second derivative of the gap for the ball as it moves (a point at distance d: |v_t|² / d, the
  /// normal turning as the ball passes it), which a ball at rest does not have.
  Vec2 bounce(std::uint32_t i, Vec2 v, Vec2 n, double press = 0.0, double curve = 0.0) const {
    const double a_n = motion.flight().normal_accel(i, bodies.body[i].v, n) + press + curve;
    // A ball at rest feels no magnetic part (only the charged flight has one).
    if constexpr (F::kBoundedHorizon) return restitution.bounce(v, n, a_n, motion.flight().normal_accel(i, Vec2{}, n) + press);
    else return restitution.bounce(v, n, a_n, a_n);
  }
};

}  // namespace turtlegas::sim::detail
