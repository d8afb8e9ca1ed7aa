// SPDX-License-Identifier: MIT
// The squeeze rule (the contacts room, contacts.hpp): the one answer for every body caught between two obstacles of infinite mass
// (walls, wall ends, moving walls and their ends, and turtles). docs/physics.md, "Wedged and
// crushed bodies", states it and proves its criteria; in short, at a contact of body i with
// obstacle B, whose previous contact was with obstacle A on the other side (n_A . n_B < 0):
//   1. held: if its free room towards A is within touch_gap (contacts.hpp), it touches both. Its
//      velocity becomes the nearest one that leaves both (the velocity of a perfectly inelastic
//      contact with both at once); if none exists (A and B parallel and closing), it is crushed.
//   2. certain crush: if A and B are parallel wall interiors (or a wall's interior and a wall end
//      the body is exactly in line with) closing at rate c > 0, nothing
//      changes their motion before the room g closes (the next keyframe is after now + g/c) and
//      the body stays between them until then (flying straight), no sequence of bounces can save
//      it: it stops bouncing and rides on B (its velocity along the normal becomes B's), meets A
//      at now + g/c, and is crushed there by rule 1.
// A ball the rule holds is an obstacle of infinite mass too (still_held), and rule 1 also counts
// the other obstacle of the body's last hold if it still touches it: with three, no velocity
// leaving all of them (leave_all) means a crush.
// A `wedged` event marks a velocity the rule set; `crushed` the removal (the engine's crush()).
// A body held by rule 1 keeps the pair in BodyStore::held, so that the round-off of a velocity
// that should leave both exactly tangent cannot make it meet them again: while its course is
// unchanged, not at all if it flies straight (a straight line leaving a line or a point at rate
// >= 0 never approaches it again), else not at that very instant.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "../room_views.hpp"
#include "carried.hpp"
#include "contacts.hpp"
#include "fold.hpp"

namespace turtlegas::sim::detail {
namespace {

/// Normals whose cross product is below this are parallel: over one radius the two obstacles'
/// separation then changes by less than the overlap budget, 1e-9 of a radius.
inline constexpr double kParallel = kOverlapBudget;

/// An obstacle as body i sees it now.
struct Side {
  bool ok = false;       ///< an obstacle of infinite mass that is still there
  bool interior = false; ///< a wall's interior, the contact foot strictly inside it
  bool point = false;    ///< a wall end (fixed, or a moving wall's, moving in a straight line), or a turtle's centre
  Vec2 at;               ///< a point's position now
  Vec2 n;                ///< unit normal from the obstacle to the body
  Vec2 u;                ///< velocity of the obstacle's surface at the contact
  double gap = 0.0;      ///< distance from the obstacle minus the contact distance
  std::uint32_t name = 0;  ///< the wall's index, or the turtle's
  bool turtle = false;
  bool ball = false;     ///< a ball the rule holds (still_held): as heavy as its holders
  std::uint32_t mover = kNone;  ///< the moving wall it is (or belongs to)
  Segment seg;           ///< a wall's segment now (interior only)
};

template <Flight Fl, bool kStep, bool kExtras>
Side side_of(const Parts<Fl, kStep, kExtras>& p, std::uint32_t i, LastPartner who, int depth = 0);

/// Whether ball k is held by the rule (docs/physics.md, "Discs squeezed by discs"): its mark is
/// current (its course, and that of a turtle or ball among its holders, unchanged since) and it
/// still touches both holders. Such a ball is as heavy as they are. A held ball among k's holders
/// is taken on its mark alone (depth 1), so that a ring of marks cannot recurse.
template <Flight Fl, bool kStep, bool kExtras>
bool still_held(const Parts<Fl, kStep, kExtras>& p, std::uint32_t k, int depth = 0) {
  const BodyStore& bs = p.bodies;
  if (bs.held.empty()) return false;
  const BodyStore::Held& h = bs.held[k];
  if (h.a.is_none() || h.b.is_none() || h.count != bs.body[k].count || bs.body[k].cell == kNone) return false;
  // (A turtle or ball obstacle that has changed course since may have let go.)
  for (const LastPartner who : {h.a, h.b})
    if (who.kind() == Partner::body && bs.body[who.index()].count != (who == h.a ? h.count_a : h.count_b)) return false;
  if (depth > 0) return true;
  p.sync(k);
  const Side A = side_of(p, k, h.a, depth + 1), B = side_of(p, k, h.b, depth + 1);
  return A.ok && B.ok && A.gap <= touch_gap(bs.body[k]) && B.gap <= touch_gap(bs.body[k]);
}

template <Flight Fl, bool kStep, bool kExtras>
Side side_of(const Parts<Fl, kStep, kExtras>& p, std::uint32_t i, LastPartner who, int depth) {
  Side s;
  if (who.is_none()) return s;
  const Body& a = p.bodies.body[i];
  const std::uint32_t k = who.index();
  switch (who.kind()) {
    case Partner::none: return s;
    case Partner::body: {
      if (p.bodies.body[k].cell == kNone) return s;
      // A ball has a finite mass, unless the rule holds it.
      if (!p.is_turtle(k) && (depth > 1 || !still_held(p, k, depth))) return s;
      const Body& t = p.bodies.body[k];
      const Vec2 F = p.arena.min_image(a.x - (t.x + (p.now - t.t) * t.v));
      const double dist = norm(F);
      if (!(dist > 0.0)) return s;
      s.n = F / dist;
      // Turtles stop when they touch: a turtle driving onto the body stops at its contact with it,
      // so its own motion never closes a squeeze (it counts as standing); one that a moving wall
      // carries goes on (carried.hpp) and closes it at the wall's speed.
      s.u = t.v;
      if (Vec2 vc; carried(p, k, vc)) s.u = vc;
      else if (dot(t.v, F) > 0.0) s.u = {};
      s.gap = dist - a.r - t.r;
      s.turtle = p.is_turtle(k);
      s.ball = !s.turtle;
      if (s.ball) s.u = t.v;  // a held ball moves only along both its holders
      s.name = s.turtle ? k - p.bodies.balls() : k;
      s.point = true;
      s.at = a.x - F;
      break;
    }
    case Partner::wall: {
      const std::uint32_t mi = p.walls.mover_of[k];
      const Segment seg = mi == kNone ? p.walls.segments[k] : p.schedule.movers[mi].segment_at(p.walls.segments[k], p.now);
      const Vec2 rel = p.arena.rel_to_segment(a.x, seg);
      const double foot = dot(rel, seg.u);
      const Vec2 off = rel - std::clamp(foot, 0.0, seg.len) * seg.u;
      const double dist = norm(off);
      if (!(dist > 0.0)) return s;
      s.n = off / dist;
      s.gap = dist - a.r;
      s.interior = foot > 0.0 && foot < seg.len;
      s.seg = seg;
      if (mi != kNone) {
        const Mover& m = p.schedule.movers[mi];
        s.u = m.u;
        if (!m.rigid()) s.u += std::clamp(foot / seg.len, 0.0, 1.0) * m.w;
        s.mover = mi;
      }
      s.name = k;
      break;
    }
    case Partner::end: {
      const WallEnd& end = p.walls.ends[k];
      const Vec2 F = p.arena.min_image(a.x - end.p);
      const double dist = norm(F);
      if (!(dist > 0.0)) return s;
      s.n = F / dist;
      s.gap = dist - a.r;
      s.name = end.wall;
      s.point = true;
      s.at = a.x - F;
      break;
    }
    case Partner::moving_end: {
      const Mover& m = p.schedule.movers[k / 2];
      const bool second = k % 2 == 1;
      const Vec2 F = a.x - m.end_at(p.walls.segments[m.wall], second, p.now);
      const double dist = norm(F);
      if (!(dist > 0.0)) return s;
      s.n = F / dist;
      s.u = m.end_velocity(second);
      s.gap = dist - a.r;
      s.name = m.wall;
      s.mover = k / 2;
      s.point = true;
      s.at = a.x - F;
      break;
    }
  }
  s.ok = true;
  return s;
}

enum class Squeeze : std::uint8_t { none, wedged, folded, crushed };

/// The squeeze events' flags: which of the body and its two obstacles are turtles, or held balls.
inline std::uint8_t squeeze_flags(bool turtle, const Side& A, const Side& B) {
  return static_cast<std::uint8_t>((turtle ? kTurtleA : 0) | (A.turtle ? kTurtleB : 0) | (B.turtle ? kTurtleC : 0) |
                                   (A.ball ? kBallB : 0) | (B.ball ? kBallC : 0));
}

/// An obstacle of body i's last hold mark other than a and b that it still touches (its mark's
/// course may have changed since: what counts is that it is still there).
template <Flight Fl, bool kStep, bool kExtras>
Side third_side(const Parts<Fl, kStep, kExtras>& p, std::uint32_t i, LastPartner a, LastPartner b) {
  if (p.bodies.held.empty()) return {};
  const BodyStore::Held& h = p.bodies.held[i];
  for (const LastPartner c : {h.a, h.b}) {
    if (c.is_none() || c == a || c == b) continue;
    const Side C = side_of(p, i, c);
    if (C.ok && C.gap <= touch_gap(p.bodies.body[i])) return C;
  }
  return {};
}

/// The velocity nearest v0 that leaves every obstacle in `sides` ((v - u) . n >= 0 for each, to
/// round-off): v0 itself, v0 brought onto one contact, or onto two at once. False when there is
/// none: the obstacles close on the body from every side, and it is crushed.
inline bool leave_all(Vec2 v0, std::initializer_list<Side> sides, Vec2& v) {
  double scale = norm(v0);
  for (const Side& s : sides) scale = std::max(scale, norm(s.u));
  const double tol = 1e-12 * scale;
  auto leaves = [&](Vec2 w) {
    for (const Side& s : sides)
      if (dot(w - s.u, s.n) < -tol) return false;
    return true;
  };
  bool found = false;
  double best = 0.0;
  auto offer = [&](Vec2 w) {
    if (!leaves(w)) return;
    const double d = norm2(w - v0);
    if (!found || d < best) v = w, best = d, found = true;
  };
  offer(v0);
  if (found) return true;
  for (const Side& s : sides) offer(v0 + (dot(s.u, s.n) - dot(v0, s.n)) * s.n);
  for (auto x = sides.begin(); x != sides.end(); ++x)
    for (auto y = x + 1; y != sides.end(); ++y) {
      const double det = cross(x->n, y->n);
      if (std::abs(det) <= kParallel) continue;
      const double cx = dot(x->u, x->n), cy = dot(y->u, y->n);
      offer({(cx * y->n.y - cy * x->n.y) / det, (cy * x->n.x - cx * y->n.x) / det});
    }
  return found;
}

/// Whether the body's centre stays over segment s (foot strictly inside) from now to now + tau,
/// flying straight at v while s translates at u: the foot is linear in time, so both ends suffice.
inline bool stays_over(Vec2 x, Vec2 v, const Side& s, double tau) {
  const Vec2 rel_then = (x + tau * v) - (s.seg.p1 + tau * s.u);
  const double foot = dot(rel_then, s.seg.u);
  return s.interior && foot > 0.0 && foot < s.seg.len;
}

/// Whether the body's centre, flying straight at v, stays on the squeeze's axis through point
/// obstacle s (moving at s.u) from now to now + tau: the axis is the other obstacle's normal n,
/// and off it by more than kParallel of the distance the two normals would no longer be parallel.
inline bool stays_on_axis(Vec2 x, Vec2 v, const Side& s, Vec2 n, double tau) {
  const Vec2 rel_then = (x + tau * v) - (s.at + tau * s.u);
  return std::abs(cross(rel_then, n)) <= kParallel * norm(rel_then);
}

/// A certain crush in a closing triangle (docs/physics.md, "Wedged and crushed bodies", rule 3):
/// body i, flying straight, between the interiors of walls A and B (not parallel) and a third
/// wall C whose three inward normals positively span the plane (lambda_A n_A + lambda_B n_B +
/// lambda_C n_C = 0 with every lambda > 0). Then sum lambda_k g_k, with g_k the free room towards
/// wall k, is the same wherever the centre is (n_k . x cancels), and it falls at the rate
/// sum lambda_k (u_k . n_k) as the walls move: the room for the centre, a triangle, shrinks to a
/// point at t* = now + sum lambda g / sum lambda c. If no wall recedes (each half-plane only
/// shrinks), the walls are translating and no keyframe comes before t*, and every point of the
/// triangle now lies over each wall's interior at now and at t* (so no end or gap lets the body
/// out), its crush is certain, whatever it meets in between. On true, v is the straight ride to
/// that point (every room falls linearly to 0 at t*), c the third wall's side.
template <Flight Fl, bool kStep, bool kExtras>
bool closing_triangle(const Parts<Fl, kStep, kExtras>& p, std::uint32_t i, const Side& A, const Side& B, Vec2& v,
                      Side& c) {
  if (p.schedule.movers.empty() || !A.interior || !B.interior || A.point || B.point) return false;
  const Body& body = p.bodies.body[i];
  auto translating = [&](const Side& s) { return s.mover == kNone || p.schedule.movers[s.mover].rigid(); };
  if (!translating(A) || !translating(B)) return false;
  const std::uint32_t walls = static_cast<std::uint32_t>(p.walls.segments.size());
  for (std::uint32_t k = 0; k < walls; ++k) {
    if (k == A.name || k == B.name) continue;
    if constexpr (kExtras)
      if (!p.bodies.layers[i].collides_with(p.walls.layers[k])) continue;
    const Side C = side_of(p, i, LastPartner::of(Partner::wall, k));
    if (!C.ok || !C.interior || !translating(C) || (A.mover == kNone && B.mover == kNone && C.mover == kNone)) continue;
    double la = cross(B.n, C.n), lb = cross(C.n, A.n), lc = cross(A.n, B.n);
    if (lc < 0.0) la = -la, lb = -lb, lc = -lc;
    if (!(la > kParallel && lb > kParallel && lc > kParallel)) continue;
    const double ca = dot(A.u, A.n), cb = dot(B.u, B.n), cc = dot(C.u, C.n);
    if (ca < 0.0 || cb < 0.0 || cc < 0.0) continue;  // a receding wall could let the room grow
    const double rate = la * ca + lb * cb + lc * cc;
    const double room = la * A.gap + lb * B.gap + lc * C.gap;
    if (!(rate > 0.0) || room < 0.0) continue;
    const double tau = room / rate;
    if (!(p.now + tau < p.schedule.next_key)) continue;
    // The triangle's corners now, relative to the centre (n_j . y = -g_j on two of its sides).
    auto corner = [](const Side& s, double gs, const Side& t, double gt) {
      const double det = cross(s.n, t.n);
      return Vec2{(-gs * t.n.y + gt * s.n.y) / det, (-gt * s.n.x + gs * t.n.x) / det};
    };
    const Vec2 corners[3] = {corner(A, A.gap, B, B.gap), corner(B, B.gap, C, C.gap), corner(C, C.gap, A, A.gap)};
    bool over = true;
    for (const Side* s : {&A, &B, &C})
      for (const Vec2 y : corners)
        for (const double when : {0.0, tau}) {
          const double foot = dot(body.x + y - (s->seg.p1 + when * s->u), s->seg.u);
          over = over && foot > 0.0 && foot < s->seg.len;
        }
    if (!over) continue;
    // The point the triangle closes on: n_k . y = c_k tau - g_k for A and B (C follows).
    const Vec2 target = corner(A, A.gap - ca * tau, B, B.gap - cb * tau);
    v = target / tau;
    c = C;
    return true;
  }
  return false;
}

/// The squeeze rule for body i, which has just been answered at a contact with `b` (its velocity
/// already set by the response); `a` is the partner of its contact before that one. Returns what
/// the rule did; on `wedged` the body's velocity has been changed and the event logged; on
/// `crushed` nothing has been changed yet (the engine removes the body and logs it).
template <Flight Fl, bool kStep, bool kExtras>
Squeeze squeeze(const Parts<Fl, kStep, kExtras>& p, std::uint32_t i, LastPartner a, LastPartner b, Side& A, Side& B) {
  if (a.is_none() || a == b) return Squeeze::none;
  A = side_of(p, i, a);
  if (!A.ok) return Squeeze::none;
  B = side_of(p, i, b);
  if (!B.ok || !(dot(A.n, B.n) < 0.0)) return Squeeze::none;
  Body& body = p.bodies.body[i];
  const Vec2 v0 = body.v;
  const double det = cross(A.n, B.n);
  const bool parallel = std::abs(det) <= kParallel;
  // How fast the two close on the body along the squeeze (parallel obstacles only).
  // (Beyond the round-off of those products: a wall sliding along itself does not close.)
  const double closing = dot(A.u, A.n) + dot(B.u, B.n);
  const bool closes = closing > kDepartFloor * (norm(A.u) + norm(B.u));
  Vec2 v = v0;
  bool held = true;
  if (A.gap <= touch_gap(body)) {
    // 1. Held between A and B, and a third obstacle it was held by before, if it still touches
    // that one too (a disc jammed between a wall, a held disc and a piston).
    if (p.motion.straight(i)) {
      const Side C = third_side(p, i, a, b);
      if (C.ok) {
        if (!leave_all(v0, {A, B, C}, v)) return Squeeze::crushed;
        if (v == v0) return Squeeze::none;
        goto done;
      }
    }
    const double ra = dot(v0 - A.u, A.n), rb = dot(v0 - B.u, B.n);
    if (ra >= 0.0 && rb >= 0.0) return Squeeze::none;  // it leaves both already
    // The elastic wedge (contacts/fold.hpp): at e = 1 the reflections between two obstacles that
    // are not parallel always end, and their limit is computed, not held: energy kept exactly.
    // (For e < 1 the sequence into a wedge is a Zeno one, and held is its limit. Bodies under a
    // field, turtles, and turtles or held balls as obstacles keep the rule below.)
    // The closed form is the limit for a body that touches only A and B. One that also touches
    // another body at this instant is part of a cluster (a disc pressed into the apex by a disc
    // a piston drives: the sequence of the cluster need not end), whose limit the engine does not
    // compute yet: rule 1 holds it as before (docs/physics.md, "The elastic wedge").
    auto touches_a_body = [&] {
      const std::uint32_t n = static_cast<std::uint32_t>(p.bodies.body.size());
      for (std::uint32_t k = 0; k < n; ++k) {
        if (k == i || p.bodies.body[k].cell == kNone) continue;
        // (Where it is now, extrapolated as side_of does: not p.sync, whose one more call site
        // changed GCC's inlining of the loop, +0.6 % of a gas's instructions.)
        const Body& o = p.bodies.body[k];
        const double gap = norm(p.arena.min_image(body.x - (o.x + (p.now - o.t) * o.v))) - body.r - o.r;
        if (gap <= touch_gap(body) + touch_gap(o)) return true;
      }
      return false;
    };
    // Scenes with moving walls keep rule 1 too: there the discs the fold lets out are compressed
    // elastically by a piston without bound (a Fermi runaway to 1.7e7 times the energy, overlap
    // 1.2e-9 r, measured on squeeze_test's held pile at e = 1) until a cluster rule answers it.
    if (!parallel && p.restitution.e == 1.0 && p.schedule.movers.empty() && p.motion.straight(i) && !p.is_turtle(i) &&
        !A.turtle && !B.turtle && !A.ball && !B.ball && !touches_a_body()) {
      if (Folded f; fold(v0, A.n, A.u, B.n, B.u, f)) {
        // The ledger: the fold keeps |v| in the frame of both contacts, so at standing walls this is
        // the round-off of the closed form.
        p.record.take_energy(p.record.stats.energy_folded, i, 0.5 * p.bodies.mass[i] * (norm2(body.v) - norm2(f.v)));
        body.v = f.v;
        p.record.note(p.t_base + p.now, EventKind::folded, i, A.name, B.name, 0);
        ++p.record.stats.folded;
        // The reflections, A first: each a collision with its obstacle.
        const std::uint64_t by_a = (f.reflections + 1) / 2, by_b = f.reflections / 2;
        (A.point ? p.record.stats.ball_wall_end : p.record.stats.ball_wall) += by_a;
        (B.point ? p.record.stats.ball_wall_end : p.record.stats.ball_wall) += by_b;
        // The mark keeps the round-off of a velocity leaving one of them tangentially from meeting it
        // again (a straight path leaving a line or a point never approaches it again).
        p.bodies.hold(i, a, b, p.now, true);
        return Squeeze::folded;
      }
    }
    if (parallel) {
      if (closes) return Squeeze::crushed;
      v = v0 + (dot(B.u, B.n) - dot(v0, B.n)) * B.n;  // it moves with B along the normal
    } else {
      const Vec2 va = v0 - ra * A.n, vb = v0 - rb * B.n;
      if (ra < 0.0 && dot(va - B.u, B.n) >= 0.0) v = va;
      else if (rb < 0.0 && dot(vb - A.u, A.n) >= 0.0) v = vb;
      else {
        // Both contacts hold: v . n_A = u_A . n_A and v . n_B = u_B . n_B (Cramer's rule).
        const double ca = dot(A.u, A.n), cb = dot(B.u, B.n);
        v = {(ca * B.n.y - cb * A.n.y) / det, (cb * A.n.x - ca * B.n.x) / det};
      }
    }
    if (!p.motion.straight(i)) {
      // Under a field that presses the body into A or B, leaving it at rate 0 would let it sink
      // at once: the rest threshold (Restitution::bounce) for both contacts, each pressed one left
      // at least at -a_n tc / 2. Parallel obstacles cannot both be left: the pressed one wins,
      // and the body, with no room to hop in, rises into the other by w^2 / (2 |a_n|) before the
      // field brings it back; so the hop there is capped at sqrt(|a_n| r 1e-9), which keeps that
      // within half the overlap budget (docs/physics.md; it hops faster than t_c then).
      const auto threshold = [&](const Side& s) {
        const double an = p.motion.flight().normal_accel(i, v, s.n);
        return an < 0.0 ? -an * p.restitution.tc / 2.0 : 0.0;
      };
      const double wa = threshold(A), wb = threshold(B);
      if (wa > 0.0 || wb > 0.0) {
        const double ca = dot(A.u, A.n) + wa, cb = dot(B.u, B.n) + wb;
        if (parallel) {
          const bool on_a = wa >= wb;
          const Side& pressed = on_a ? A : B;
          const double hop = on_a ? wa : wb;  // = |a_n| tc / 2
          const double capped = std::min(hop, std::sqrt(2.0 * hop / p.restitution.tc * body.r * kOverlapBudget));
          v += (dot(pressed.u, pressed.n) + capped - dot(v, pressed.n)) * pressed.n;
          if (p.restitution.e == 1.0) {
            // Elastic: keep the speed relative to the pressed obstacle, as Restitution::bounce does
            // at e = 1 (it turned v to leave at the threshold, taking that from the tangential
            // part); the cap above would otherwise drain the slide a little at every hop. The
            // hop comes back at the speed it left with, so this adds no energy over a hop.
            const Vec2 rel = v - pressed.u, rel0 = v0 - pressed.u;
            const double wn = dot(rel, pressed.n);
            const Vec2 t = rel - wn * pressed.n;
            const double want = dot(rel0, rel0) - wn * wn, t2 = dot(t, t);
            if (want > 0.0 && t2 > 0.0) v = pressed.u + wn * pressed.n + std::sqrt(want / t2) * t;
          }
        } else {
          v = {(ca * B.n.y - cb * A.n.y) / det, (cb * A.n.x - ca * B.n.x) / det};
        }
      }
    }
  } else {
    // 2. A certain crush: ride on B until the room closes. Between two wall interiors, or a wall's
    // interior and a wall end or turtle the body is exactly in line with (head on: a piston
    // driving it onto the end of a wall), which it cannot slide off when it does not move across
    // the axis.
    if (!p.motion.straight(i)) return Squeeze::none;
    if (!parallel) {
      // 3. Three walls closing on the body from every side: a certain crush at a point.
      Side C;
      if (!closing_triangle(p, i, A, B, v, C)) return Squeeze::none;
      held = false;
      goto done;
    }
    if (!closes) return Squeeze::none;
    if (!(A.interior || A.point) || !(B.interior || B.point) || (A.point && B.point)) return Squeeze::none;
    const double tau = A.gap / closing;
    if (!(p.now + tau < p.schedule.next_key)) return Squeeze::none;
    // A turtle keeps its velocity while its command runs, and its program can change it only at a
    // control boundary (a touch is delivered there): certain until the earlier of the two.
    auto turtle_keeps = [&](const Side& s) {
      if (!s.turtle) return true;
      const double boundary = (std::floor((p.t_base + p.now) / p.dt) + 1.0) * p.dt - p.t_base;
      return p.now + tau <= boundary && p.now + tau <= p.bodies.end[p.bodies.balls() + s.name];
    };
    if (!turtle_keeps(A) || !turtle_keeps(B)) return Squeeze::none;
    v = v0 + (dot(B.u, B.n) - dot(v0, B.n)) * B.n;
    auto keeps = [&](const Side& s, const Side& other) {
      return s.point ? stays_on_axis(body.x, v, s, other.n, tau) : stays_over(body.x, v, s, tau);
    };
    if (!keeps(A, B) || !keeps(B, A)) return Squeeze::none;
    held = false;  // it must meet A at t*: no mark
  }
done:
  const std::uint32_t nb = p.bodies.balls();
  const bool turtle = p.is_turtle(i);
  if (!turtle) p.record.take_energy(p.record.stats.energy_wedged, i, 0.5 * p.bodies.mass[i] * (norm2(body.v) - norm2(v)));
  body.v = v;
  p.record.note(p.t_base + p.now, EventKind::wedged, turtle ? i - nb : i, A.name, B.name,
                squeeze_flags(turtle, A, B));
  ++p.record.stats.wedged;
  if (held) p.bodies.hold(i, a, b, p.now, p.motion.straight(i));
  return Squeeze::wedged;
}

/// Discs squeezed by discs: a ball held by the rule between two obstacles (still_held) that
/// another ball pushes into them (the push, along the line of centres, is a sum of their normals
/// turned against it: it can take no part of it) cannot move that way: it is as heavy as they are.
/// The pusher bounces off it as off an obstacle of infinite mass moving at its velocity (with the
/// rest threshold, so a pile rests on a wedged disc as on a wall); the held ball keeps its course
/// and its mark. Returns the pusher, whose contact the squeeze rule then answers like any contact
/// with an obstacle of infinite mass, or kNone (nothing done) when neither ball is so held, or
/// the push has a component that the obstacles would let it take.
/// (Without it, a disc pressed onto a disc wedged in a V exchanged round-off velocities of 1e-19
/// with it and the walls for ever at one instant, in step mode.)
template <Flight Fl, bool kStep, bool kExtras>
[[gnu::noinline, gnu::cold]] std::uint32_t push_held(const Parts<Fl, kStep, kExtras>& p, std::uint32_t i, std::uint32_t j) {
  // (Out of line and cold: inlined into the ball-ball path it changed GCC's inlining of the
  // engine's loop and cost 1.25 % more instructions on a gas that never squeezes.)
  const BodyStore& bs = p.bodies;
  auto holds = [&](std::uint32_t k, std::uint32_t other) {
    if (!still_held(p, k)) return false;
    p.sync(other);
    const BodyStore::Held& h = bs.held[k];
    const Side A = side_of(p, k, h.a, 1), B = side_of(p, k, h.b, 1);
    const Vec2 d = p.arena.min_image(bs.body[k].x - bs.body[other].x);  // the way `other` pushes k
    // d = -(alpha n_A + beta n_B) with alpha, beta >= 0 (to round-off): the holders take all of it.
    const double det = cross(A.n, B.n);
    if (std::abs(det) <= kParallel) return dot(d, A.n) < 0.0 && dot(d, B.n) < 0.0;
    const double alpha = -cross(d, B.n) / det, beta = -cross(A.n, d) / det;
    const double tol = -kParallel * norm(d);
    return alpha >= tol && beta >= tol;
  };
  std::uint32_t k = j, other = i;
  if (!holds(j, i)) {
    if (!holds(i, j)) return kNone;
    k = i;
    other = j;
  }
  Body& o = p.bodies.body[other];
  const Body& bk = p.bodies.body[k];
  const Vec2 F = p.arena.min_image(o.x - bk.x);
  const double dist = norm(F);
  p.record.note_contact(o.r + bk.r - dist, std::min(o.r, bk.r));
  const Vec2 n = F / dist;
  const Vec2 va = o.v;
  o.v = bk.v + p.bounce(other, o.v - bk.v, n);  // as off a wall: the plain restitution
  if (p.record.impulses) [[unlikely]]
    p.impulse(EventKind::ball_ball, other, k, p.bodies.mass[other] * (o.v - va), -F);
  p.count(p.record.stats.ball_ball, EventKind::ball_ball, i, j);
  p.changed(other);
  p.bodies.last[other] = LastPartner::of(Partner::body, k);
  return other;
}

}  // namespace
}  // namespace turtlegas::sim::detail
