// SPDX-License-Identifier: MIT
// Interactions, one section per pair kind: ball-ball, turtle-body (a turtle with a ball or
// another turtle), body-wall, body-wall end, and moving walls (their interior and their two
// ends). Each has
//   - predict: the time of impact of one candidate pair, offered to the body's Pending (it reads
//     a Look; the flight chooses the time-of-impact function and whether the pair's last
//     collision rules it out);
//   - apply: the response at the contact, with its record (it receives Parts; it returns the
//     bodies whose course changed, which the engine then predicts afresh);
//   - validate: how deep the contact was when it happened (EventRecord::note_contact), the
//     engine's running check on its own times of impact.
// The neighbourhood scans (neighbourhood.hpp) decide which candidates each body looks at.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "contacts/carried.hpp"
#include "contacts/contacts.hpp"
#include "room_views.hpp"
#include "turtlegas/sim/toi.hpp"

namespace turtlegas::sim::detail {
namespace {

/// The bodies an event changed, to be predicted afresh in this order.
struct Changed {
  std::uint32_t first;
  std::uint32_t second = kNone;
};

/// The common end of every response: body i changed course (Parts::changed: predictions made
/// with it are stale) and met `partner` last (the contacts room's LastPartner rule, contacts.hpp).
template <Flight Fl, bool kStep, bool kExtras>
[[gnu::always_inline]] inline Changed answered(const Parts<Fl, kStep, kExtras>& p, std::uint32_t i, LastPartner partner) {
  p.changed(i);
  p.bodies.last[i] = partner;
  return {i};
}

/// The same for two bodies that met each other.
template <Flight Fl, bool kStep, bool kExtras>
[[gnu::always_inline]] inline Changed answered(const Parts<Fl, kStep, kExtras>& p, std::uint32_t i, std::uint32_t j) {
  p.changed(i);
  p.changed(j);
  p.bodies.last[i] = LastPartner::of(Partner::body, j);
  p.bodies.last[j] = LastPartner::of(Partner::body, i);
  return {i, j};
}

// ---------------------------------------------------------------------------------------------
// Ball-ball

/// Ball i (at its own time, now) and ball j seen through `shift` (a periodic image).
template <Flight F, bool kExtras>
[[gnu::always_inline]] inline void predict_ball_ball(const Look<F, kExtras>& l, std::uint32_t i, const Body& bi,
                                                     std::uint32_t j, Vec2 shift, Pending& p) {
  if (j == i || !l.meets(i, j)) return;
  const Body& bj = l.bodies.body[j];
  const double dtj = l.now - bj.t;
  const F& f = l.motion.flight();
  const FieldState sj = flight_state(f, j, bj.x, bj.v, dtj);
  const Vec2 r = sj.x + shift - bi.x;
  const Vec2 vj = sj.v;
  const double t = l.now + f.toi_balls(i, j, r, bi.v, vj, bi.r + bj.r, p.t_coll - l.now);
  if (t < p.t_coll) {
    // Checked only for a winner: most candidates miss, and last[j] is a cache miss (contacts.hpp).
    if (f.straight_pair(i, j)) {
      if (just_met_body(l.bodies, true, i, j)) return;  // (skip_body without the marks: push_held)
      if (grazes_pair(r, vj - bi.v, bi.r + bj.r, std::min(bi.r, bj.r))) return;
    }
    p.take(t, Partner::body, j, bj.count);
  }
}

template <Flight Fl, bool kStep, bool kExtras>
Changed apply_ball_ball(const Parts<Fl, kStep, kExtras>& w, std::uint32_t i, std::uint32_t j) {
  w.sync(i);
  w.sync(j);
  Body& a = w.bodies.body[i];
  Body& b = w.bodies.body[j];
  const Vec2 F = w.arena.min_image(b.x - a.x);
  const double sigma = a.r + b.r;
  w.record.note_contact(sigma - norm(F), std::min(a.r, b.r));
  const double e = w.restitution.for_pair(i, j, w.now);
  const Vec2 va = a.v;
  respond_disc_disc(a.v, b.v, w.bodies.mass[i], w.bodies.mass[j], F, e);
  if (w.record.impulses) [[unlikely]]
    w.impulse(EventKind::ball_ball, i, j, w.bodies.mass[i] * (a.v - va), -F);
  w.count(w.record.stats.ball_ball, EventKind::ball_ball, i, j);
  return answered(w, i, j);
}

// ---------------------------------------------------------------------------------------------
// Turtle-body: a turtle (a disc of infinite mass that flies straight) with a ball or a turtle

/// A pair one of whose bodies is a turtle on an arc: the field searches of two flights (field_toi.hpp),
/// up to the end of the arcs (the pair's relative motion is not straight: no pair is skipped for
/// having just met).
template <Flight F, bool kExtras>
[[gnu::noinline]] void predict_arc_pair(const Look<F, kExtras>& l, std::uint32_t i, const Body& bi, std::uint32_t j, Vec2 shift,
                                        Pending& p) {
  const Body& bj = l.bodies.body[j];
  const FieldState sj = l.motion.state(bj, j, l.now - bj.t);
  const double horizon = l.horizon(j, l.horizon(i, p.t_coll)) - l.now;
  if (!(horizon > 0.0)) return;
  const double t = l.now + l.motion.toi_arc_pair(i, bi.v, j, sj.x + shift - bi.x, sj.v, bi.r + bj.r, horizon);
  if (t < p.t_coll) p.take(t, Partner::body, j, bj.count);
}

/// Turtle j, seen from body i (a ball or a turtle).
template <Flight F, bool kExtras>
[[gnu::always_inline]] inline void predict_turtle(const Look<F, kExtras>& l, std::uint32_t i, const Body& bi, std::uint32_t j, Vec2 shift,
                    Pending& p) {
  if (j == i || !l.meets(i, j)) return;
  if (l.motion.any_arcs() && (l.motion.arcs(i) || l.motion.arcs(j))) [[unlikely]]
    return predict_arc_pair(l, i, bi, j, shift, p);
  const Body& bj = l.bodies.body[j];
  const Vec2 rel = bi.x - (bj.x + (l.now - bj.t) * bj.v + shift);
  const Vec2 v = bi.v - bj.v;
  const double t = l.now + l.motion.toi_point(i, rel, v, bj.v, bi.r + bj.r, p.t_coll - l.now);
  if (t < p.t_coll && !skip_body(l.bodies, l.motion.straight(i), i, j, t))
    p.take(t, Partner::body, j, bj.count);
}

/// Ball j (which may fall), seen from turtle i.
template <Flight F, bool kExtras>
[[gnu::always_inline]] inline void predict_ball_from_turtle(const Look<F, kExtras>& l, std::uint32_t i, const Body& bi, std::uint32_t j,
                              Vec2 shift, Pending& p) {
  if (!l.meets(i, j)) return;
  if (l.motion.any_arcs() && l.motion.arcs(i)) [[unlikely]]
    return predict_arc_pair(l, i, bi, j, shift, p);
  const Body& bj = l.bodies.body[j];
  const double dtj = l.now - bj.t;
  const F& f = l.motion.flight();
  const Vec2 rel = f.pos(j, bj.x, bj.v, dtj) + shift - bi.x;
  const Vec2 v = f.vel(j, bj.v, dtj) - bi.v;
  const double t = l.now + f.toi_point(j, rel, v, bi.v, bi.r + bj.r, p.t_coll - l.now);
  if (t < p.t_coll && !skip_body(l.bodies, f.straight(j), j, i, t))
    p.take(t, Partner::body, j, bj.count);
}

template <Flight Fl, bool kStep, bool kExtras>
Changed apply_turtle_body(const Parts<Fl, kStep, kExtras>& w, std::uint32_t i, std::uint32_t j) {
  w.sync(i);
  w.sync(j);
  const std::uint32_t nb = w.bodies.balls();
  // Name the pair (turtle, other) with the turtle first.
  const std::uint32_t t = w.is_turtle(i) ? i : j;
  const std::uint32_t o = t == i ? j : i;
  Body& bt = w.bodies.body[t];
  Body& bo = w.bodies.body[o];
  const Vec2 F = w.arena.min_image(bo.x - bt.x);  // from the turtle to the other body
  const double dist = norm(F);
  w.record.note_contact(bt.r + bo.r - dist, std::min(bt.r, bo.r));
  const Vec2 n = F / dist;
  if (!w.is_turtle(o)) {
    // The turtle stops dead (or bounces) at the contact first; the ball then bounces off it as
    // off a wall of infinite mass moving at the turtle's new velocity. (Against the old velocity,
    // a ball that caught up with a turtle from behind would keep closing on it once it stopped.)
    w.touch(t, EventKind::turtle_ball, o, -n);
    // A turtle a moving wall carries goes on at the wall's speed (it used to stop, be caught by the
    // wall at once and meet the ball again, for ever at one instant).
    if (Vec2 vc; carried(w, t, vc)) bt.v = vc;  // contacts/carried.hpp
    const Vec2 rel = bo.v - bt.v;
    if (dot(rel, n) < 0.0) bo.v = bt.v + w.bounce(o, rel, n);
    w.count(w.record.stats.turtle_ball, EventKind::turtle_ball, t - nb, o);
  } else {
    w.count(w.record.stats.turtle_turtle, EventKind::turtle_turtle, t - nb, o - nb);
    w.touch(t, EventKind::turtle_turtle, o - nb, -n);
    w.touch(o, EventKind::turtle_turtle, t - nb, n);
    // A carried turtle goes on; one it meets that is not carried is pushed along by it (both have
    // infinite mass) at its normal speed, carried by the same wall through it.
    Vec2 vt, vo;
    const bool ct = carried(w, t, vt), co = carried(w, o, vo);
    if (ct) bt.v = vt;
    if (co) bo.v = vo;
    if (ct != co) {
      const std::uint32_t c = ct ? t : o, q = ct ? o : t;
      const Vec2 nq = ct ? n : -n;  // from the carrier to the other
      const double un = dot(ct ? vt : vo, nq);
      if (un > 0.0) carry(w.turtles, q - nb, w.bodies.body[q], un * nq, w.turtles.pushed_by[c - nb], c - nb);
    }
  }
  return answered(w, t, o);
}

// ---------------------------------------------------------------------------------------------
// Body-wall: a fixed wall's interior (a moving wall's is predicted with the moving walls, below,
// and applied here)

template <Flight F, bool kExtras>
[[gnu::always_inline]] inline void predict_wall(const Look<F, kExtras>& l, std::uint32_t i, const Body& bi, std::uint32_t w, Vec2 shift,
                  Pending& p) {
  // skip() in two halves (contacts.hpp): the wall just met is left out before the search.
  if (!l.meets_wall(i, w) || just_met(l.bodies, l.motion.straight(i), i, LastPartner::of(Partner::wall, w))) return;
  // A ball sliding along the wall keeps touching it without meeting it (the sliding flight).
  if (slides_on(l.motion.flight(), i, w)) [[unlikely]] return;
  const Segment& s = l.walls.segments[w];
  // Relative to the wall's first end, so walls far from the origin lose nothing.
  const double t = l.now + l.motion.toi_segment(i, bi.x - (s.p1 + shift), bi.v, Vec2{}, s, bi.r, l.horizon(i, p.t_coll) - l.now);
  if (t < p.t_coll && !(l.bodies.held_against(i, LastPartner::of(Partner::wall, w), t)))
    p.take(t, Partner::wall, w);
}

template <Flight Fl, bool kStep, bool kExtras>
Changed apply_wall(const Parts<Fl, kStep, kExtras>& p, std::uint32_t i, std::uint32_t w) {
  p.sync(i);
  Body& a = p.bodies.body[i];
  const std::uint32_t mi = p.walls.mover_of[w];
  const Segment s = mi == kNone ? p.walls.segments[w] : p.schedule.movers[mi].segment_at(p.walls.segments[w], p.now);
  // The velocity of the wall's material point at the contact: the ends' velocities interpolated
  // at the foot (the same for every point of a translating wall).
  Vec2 u{};
  bool turning = false;
  double press = 0.0;  // the body's acceleration along n relative to a turning wall's line (< 0: pressed)
  const double d = dot(p.arena.rel_to_segment(a.x, s), s.n);
  if (mi != kNone) {
    const Mover& m = p.schedule.movers[mi];
    u = m.u;
    if (!m.rigid()) {
      turning = true;
      u += std::clamp(dot(a.x - s.p1, s.u) / s.len, 0.0, 1.0) * m.w;
      // Its line accelerates relative to the body even where its material point does not move
      // (a pivot): the rest threshold counts that press as it counts a field's.
      const Vec2 vb = p.is_turtle(i) ? Vec2{} : a.v;
      press = (d >= 0.0 ? 1.0 : -1.0) * deforming_line_accel(a.x - s.p1, vb - m.u, Vec2{}, m.d_at(p.now), m.w);
    }
  }
  const Vec2 n = d >= 0.0 ? s.n : -s.n;
  p.record.note_contact(a.r - std::abs(d), a.r);
  if (p.is_turtle(i)) {
    p.count(p.record.stats.turtle_wall, EventKind::turtle_wall, i - p.bodies.balls(), w);
    p.touch(i, EventKind::turtle_wall, w, n);
    // A moving wall pushing a turtle carries it along at its normal speed (both have infinite
    // mass), until the wall's next keyframe. A turning or stretching wall's push changes along the
    // way, so it knocks the turtle off instead, at twice its normal speed (an elastic bounce off
    // the wall), which the wall can only catch up with by speeding up; at least at the rest
    // threshold's speed for its press (at a pivot the normal speed is 0).
    const double un = dot(u, n);
    double knock = !turning ? un : std::max(2.0 * un, -press * p.restitution.tc / 2.0);
    if (turning && knock > 0.0) knock = std::max(knock, kDepartFloor * norm(u));  // (round-off: as for a ball, below)
    if (knock > 0.0) carry(p.turtles, i - p.bodies.balls(), a, knock * n, mi, kNone);  // contacts/carried.hpp
  } else {
    const Vec2 va = a.v;
    a.v = u + p.bounce(i, a.v - u, n, press);
    if (turning) {
      // A turning line's approach rate (the solver's) and the normal speed of its point at the foot
      // (this response's) agree only to round-off: a ball left at a rate within it (riding the arm
      // at its speed) could be "touching and approaching" again at once, for ever. It leaves at
      // kDepartFloor of its speed at least (contacts.hpp).
      const double floor = kDepartFloor * (norm(a.v) + norm(u)), rn = dot(a.v - u, n);
      if (rn < floor) a.v += (floor - rn) * n;
    }
    if (p.record.impulses) [[unlikely]]
      p.impulse(EventKind::ball_wall, i, w, p.bodies.mass[i] * (a.v - va), std::abs(d) * n);
    p.count(p.record.stats.ball_wall, EventKind::ball_wall, i, w);
  }
  return answered(p, i, LastPartner::of(Partner::wall, w));
}

// ---------------------------------------------------------------------------------------------
// Body-wall end: a fixed wall's end point, one per distinct point

/// What a point's curvature adds to the gap's second derivative for a ball passing it with
/// velocity v (relative to the point) at distance `dist` along the unit normal n: |v_t|² / dist.
/// The gap to a face bends only with the ball's own acceleration; the gap to a point also because
/// the normal turns as the ball goes by, always away. The rest threshold must count it (issue 28
/// item 5): without it a charged ball whose circle dips 1e-9 of a radius into an end from inside,
/// pressed towards the end by B, was lifted off it at the threshold's speed instead of its own
/// grazing one, and met it again 3.7e-5 s early, every turn.
inline double end_curvature(Vec2 v, Vec2 n, double dist) {
  const Vec2 vt = v - dot(v, n) * n;
  return dot(vt, vt) / dist;
}

template <Flight F, bool kExtras>
[[gnu::always_inline]] inline void predict_end(const Look<F, kExtras>& l, std::uint32_t i, const Body& bi, std::uint32_t e, Vec2 shift,
                 Pending& p) {
  // skip() in two halves (contacts.hpp): the end just met is left out before the search.
  if (!l.meets_end(i, e) || just_met(l.bodies, l.motion.straight(i), i, LastPartner::of(Partner::end, e))) return;
  const Vec2 rel = bi.x - (l.walls.ends[e].p + shift);
  const double t = l.now + l.motion.toi_point(i, rel, bi.v, Vec2{}, bi.r, l.horizon(i, p.t_coll) - l.now);
  if (t < p.t_coll && !(l.bodies.held_against(i, LastPartner::of(Partner::end, e), t))) {
    // A ball sliding along a wall passes its ends at the contact distance only when the slide
    // ends there (the sliding flight's own event): until then it cannot meet them.
    if (slides_to(l.motion.flight(), i, l.walls.ends[e].p)) [[unlikely]] return;
    // A straight path that passes an end at the contact distance (a disc sliding along a wall
    // past the joint with the next one) "touches and approaches" it by round-off only: a graze
    // (contacts.hpp, kEndGraze).
    if (l.motion.straight(i) && grazes_end(rel, bi.v, bi.r)) return;
    p.take(t, Partner::end, e);
  }
}

template <Flight Fl, bool kStep, bool kExtras>
Changed apply_end(const Parts<Fl, kStep, kExtras>& p, std::uint32_t i, std::uint32_t e) {
  p.sync(i);
  Body& a = p.bodies.body[i];
  const WallEnd& end = p.walls.ends[e];
  const Vec2 F = p.arena.min_image(a.x - end.p);
  const double dist = norm(F);
  p.record.note_contact(a.r - dist, a.r);
  if (p.is_turtle(i)) {
    p.count(p.record.stats.turtle_wall_end, EventKind::turtle_wall_end, i - p.bodies.balls(), end.wall);
    p.touch(i, EventKind::turtle_wall_end, end.wall, F / dist);
  } else {
    const Vec2 va = a.v;
    a.v = p.bounce(i, a.v, F / dist, 0.0, end_curvature(a.v, F / dist, dist));
    if (p.record.impulses) [[unlikely]] p.impulse(EventKind::ball_wall_end, i, end.wall, p.bodies.mass[i] * (a.v - va), F);
    p.count(p.record.stats.ball_wall_end, EventKind::ball_wall_end, i, end.wall);
  }
  return answered(p, i, LastPartner::of(Partner::end, e));
}

// ---------------------------------------------------------------------------------------------
// Moving walls: outside the table, checked by every prediction up to the next keyframe (which
// makes every body predict again), in the wall's frame, where a body flies with v - u. A contact
// with the interior is applied as a wall's (apply_wall); the ends are `moving_end` partners,
// numbered 2 mover + (0: first end, 1: second).

template <Flight F, bool kExtras>
[[gnu::always_inline]] inline void predict_mover(const Look<F, kExtras>& l, std::uint32_t i, const Body& bi, std::uint32_t mi, Pending& p) {
  const Mover& m = l.schedule.movers[mi];
  const std::uint32_t w = m.wall;
  if (!l.meets_wall(i, w)) return;
  const Segment& s = l.walls.segments[w];
  const Vec2 p1 = m.p1_at(l.now);
  const Vec2 v = bi.v - m.u;
  const double horizon = std::min(l.horizon(i, p.t_coll), l.schedule.next_key);
  const bool straight = l.motion.straight(i);
  // Relative to a turning or stretching wall no motion is straight: no straight-line argument
  // rules out meeting the same wall again.
  const bool straight_to_wall = straight && m.rigid();
  const LastPartner wall = LastPartner::of(Partner::wall, w);
  double t_wall = kNever;
  if (!m.rigid()) {
    t_wall = l.now + l.motion.toi_deforming_segment(i, bi.x - p1, v, m.d_at(l.now), m.w, bi.r, horizon - l.now);
  } else if (!just_met(l.bodies, straight_to_wall, i, wall)) {  // (before the search)
    t_wall = l.now + l.motion.toi_segment(i, bi.x - p1, v, m.u, s, bi.r, horizon - l.now);
  }
  if (t_wall < p.t_coll && t_wall <= horizon && !l.bodies.held_against(i, wall, t_wall))
    p.take(t_wall, Partner::wall, w);
  for (std::uint32_t which = 0; which < 2; ++which) {
    const std::uint32_t code = 2 * mi + which;
    const LastPartner end = LastPartner::of(Partner::moving_end, code);
    if (just_met(l.bodies, straight, i, end)) continue;  // (before the search)
    // Each end moves in a straight line, so its contacts have the closed forms of a fixed point.
    const Vec2 e = m.end_at(s, which == 1, l.now);
    const Vec2 ve = which == 0 ? v : v - m.w;  // the body's velocity relative to that end
    const double t = l.now + l.motion.toi_point(i, bi.x - e, ve, which == 0 ? m.u : m.u + m.w, bi.r, horizon - l.now);
    if (t < p.t_coll && t <= horizon && !l.bodies.held_against(i, end, t)) p.take(t, Partner::moving_end, code);
  }
}

template <Flight Fl, bool kStep, bool kExtras>
Changed apply_moving_end(const Parts<Fl, kStep, kExtras>& p, std::uint32_t i, std::uint32_t code) {
  p.sync(i);
  Body& a = p.bodies.body[i];
  const Mover& m = p.schedule.movers[code / 2];
  const bool second = code % 2 == 1;
  const Vec2 e = m.end_at(p.walls.segments[m.wall], second, p.now);
  const Vec2 ue = m.end_velocity(second);
  const Vec2 F = a.x - e;
  const double dist = norm(F);
  p.record.note_contact(a.r - dist, a.r);
  if (p.is_turtle(i)) {
    const Vec2 n = F / dist;
    p.count(p.record.stats.turtle_wall_end, EventKind::turtle_wall_end, i - p.bodies.balls(), m.wall);
    p.touch(i, EventKind::turtle_wall_end, m.wall, n);
    // The end does for a turtle what the face does (apply_wall): both have infinite mass, so the
    // turtle cannot stop dead in its way (it did, and the end swept through it, issue 28 item 7).
    // A translating wall's end carries it at its normal speed, the perfectly inelastic contact:
    // head on it pushes it along as a face would; off its line the end then slides past it
    // (relative to the end the turtle moves along the tangent, and the gap opens), and the turtle
    // goes on at that speed, knocked off, until the wall's next keyframe ends the push
    // (contacts/carried.hpp). A turning wall's end knocks it off at twice its normal speed, as
    // the turning face does.
    const double un = dot(ue, n);
    double knock = m.rigid() ? un : 2.0 * un;
    if (!m.rigid() && knock > 0.0) knock = std::max(knock, kDepartFloor * norm(ue));
    if (knock > 0.0) carry(p.turtles, i - p.bodies.balls(), a, knock * n, code / 2, kNone);
  } else {
    const Vec2 va = a.v;
    a.v = ue + p.bounce(i, a.v - ue, F / dist, 0.0, end_curvature(a.v - ue, F / dist, dist));
    if (p.record.impulses) [[unlikely]] p.impulse(EventKind::ball_wall_end, i, m.wall, p.bodies.mass[i] * (a.v - va), F);
    p.count(p.record.stats.ball_wall_end, EventKind::ball_wall_end, i, m.wall);
  }
  return answered(p, i, LastPartner::of(Partner::moving_end, code));
}

}  // namespace
}  // namespace turtlegas::sim::detail
