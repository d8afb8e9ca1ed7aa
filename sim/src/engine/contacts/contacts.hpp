// SPDX-License-Identifier: MIT
// The contacts room: how an exact engine stops serving contacts at one instant for ever.
//
// THE PRINCIPLE. A contact answered at t is not met again at t unless a course changed; bodies
// touching at one instant form a cluster, answered in a bounded number of events.
//
// An exact engine computes times of impact in floating point. After a response, a pair that is
// touching can look "touching and approaching" by a few ulps of a normal speed, and would meet
// again at once, for ever, at the same instant. Six mechanisms keep the principle, each for one
// way a contact could come back (docs/physics.md: "Contact semantics", "Tolerances, and why each
// is safe", "Wedged and crushed bodies"):
//   1. just met (LastPartner, records.hpp): a pair whose relative motion is a straight line
//      cannot meet again until one of them changes course (skip(), below);
//   2. grazes: a closest approach within a named tolerance of contact is not a contact
//      (grazes_pair, grazes_end, grazes_line, below);
//   3. departure floors: a response whose normal speed is exact only up to round-off leaves at
//      kDepartFloor of the speeds at least (interactions.hpp: turning walls; squeeze.hpp);
//   4. squeeze marks: a body answered by the squeeze rule is not met again by its two obstacles
//      while its course is unchanged (BodyStore::held_against, in skip());
//   5. carried turtles: a turtle a translating moving wall pushes goes on at the wall's speed
//      instead of stopping dead and being caught at once (carried.hpp);
//   6. the TC rule and the rest threshold: an inelastic cluster cannot collapse into infinitely
//      many collisions in finite time (restitution.hpp).
// A body caught between obstacles of infinite mass is answered by the squeeze rule (squeeze.hpp),
// once per contact, from the one hook after a contact (resolve.hpp). An elastic ball touching two
// walls that are not parallel is not held: the zero-time reflections end, and their limit is
// computed in closed form (fold.hpp, "The elastic wedge").
//
// Every tolerance is named here once, with why it is safe. Nothing here may cost the gas a thing:
// each test runs only for a winning candidate, and inlines to what it replaced. GCC's inlining of
// the engine's loop is sensitive to the shape of these tests (callgrind inside World::advance_to,
// docs/performance.md): this header is read early (flights.hpp), so it includes nothing of the
// engine but the records, and takes the body store, the walls and their schedule as template
// arguments (pulling their headers in ahead of flights.hpp reordered the unit: +1.5 % of the
// gas's instructions for the same code); see also grazes_end and skip.
#pragma once

#include <cmath>
#include <cstdint>

#include "../records.hpp"
#include "turtlegas/sim/vec2.hpp"

namespace turtlegas::sim::detail {

/// The engine's overlap budget, relative to a radius: how deep a contact may be (validated by
/// EventRecord::note_contact) and so how far from contact a body still counts as touching.
inline constexpr double kOverlapBudget = 1e-9;

/// Relative round-off of a coordinate: 2^-46 = 128 ulps of |x| + |y|, the error of a position
/// formed by a few flights and rebases far from the origin.
inline constexpr double kPositionRoundOff = 0x1p-46;

/// kTouchGap: the free room (distance beyond contact) up to which a disc of radius r at x counts
/// as touching an obstacle: the overlap budget plus the round-off of positions far from the
/// origin. The squeeze rule's "held" and a carried turtle's "still pushed" both use it.
inline double touch_gap(double r, Vec2 x) {
  return kOverlapBudget * r + kPositionRoundOff * (std::abs(x.x) + std::abs(x.y));
}
inline double touch_gap(const Body& b) { return touch_gap(b.r, b.x); }

/// Whether free room `gap` is touching for a disc of radius r at x (touch_gap).
inline bool touching(double gap, double r, Vec2 x) { return gap <= touch_gap(r, x); }

/// kPairGraze: two discs whose straight relative path passes within kPairGraze r_min of the
/// contact distance only graze. Ignoring such a graze overlaps them by no more than that, far
/// below the overlap budget; a pass 1e-13 inside contact still collides (hard_cases_test). A
/// buckling chain's pairs pass within (1e-13)^2 of it, plus a few ulps of round-off.
inline constexpr double kPairGraze = 1e-14;

/// kEndGraze: a straight path passing a wall end within kEndGraze of a radius of the contact
/// distance only grazes it (a disc sliding along a wall past the joint with the next one). Its
/// response would turn the velocity by round-off, and a squeeze between two such joints could
/// repeat without end; ignoring it overlaps the end by no more than that.
inline constexpr double kEndGraze = 1e-10;

/// kGrazeRate: a turtle whose normal rate towards a wall's line is below kGrazeRate of its speed
/// drives along it (its heading's sine and cosine against the normal are exact to ~1e-16): over a
/// drive of 1e4 radii the ignored rate drifts it 1e-9 of a radius, the overlap budget.
inline constexpr double kGrazeRate = 1e-13;

/// kDepartFloor: a response whose normal speed agrees with the obstacle's only to round-off (a
/// turning line's approach rate against its point's speed; two obstacles closing) leaves, or
/// counts as closing, only beyond 2^-40 (~1e-12) of the speeds involved: far below any physics,
/// far above the round-off of those products.
inline constexpr double kDepartFloor = 0x1p-40;

/// Whether two discs whose centres separate by r + w t (in a straight line) only graze: the
/// closest approach of that line, |r x w| / |w|, is within kPairGraze r_min of the contact
/// distance sigma (r_min: the smaller radius). In a chain of touching discs that slide past each
/// other (a buckling chain a piston drives into a disc held in a V), each contact answered at one
/// instant left its neighbours "touching and approaching" by round-off (1e-13 of their speed), and
/// the chain served those contacts at that instant for ever.
/// It runs for every winning candidate of a straight pair, so it is squared: (r x w)^2 against
/// (sigma - kPairGraze r_min)^2 |w|^2, no root and no division (both sides >= 0: the same
/// comparison). The squares are the ones toi_disc_disc takes, finite for every pair whose time it
/// found (validate.cpp keeps speed times distance below 1e154).
inline bool grazes_pair(Vec2 r, Vec2 w, double sigma, double r_min) {
  const double c = cross(r, w), s = sigma - kPairGraze * r_min, w2 = norm2(w);
  return c * c >= s * s * w2 && w2 > 0.0;  // (w2 > 0 tested first cost 0.6 % more)
}

/// Whether a disc of radius r at rel from a fixed point, flying straight at v, only grazes it:
/// its closest approach |rel x v| / |v| is within kEndGraze of a radius of contact. (Always
/// inlined: as a plain inline function it changed GCC's inlining of the engine's loop, +0.7 % of
/// the gas's instructions; forced, the loop is compiled as when the test was written in place.)
[[gnu::always_inline]] inline bool grazes_end(Vec2 rel, Vec2 v, double r) {
  const double speed = norm(v);
  return speed > 0.0 && std::abs(cross(rel, v)) / speed >= r * (1.0 - kEndGraze);
}

/// Whether a turtle moving at v relative to a wall of unit normal n drives along its line: a
/// normal rate within kGrazeRate of its speed (it would otherwise stop at once).
inline bool grazes_line(Vec2 v, Vec2 n) { return std::abs(dot(v, n)) <= kGrazeRate * norm(v); }

/// Mechanism 1, the LastPartner rule: body i, whose motion relative to `partner` (a wall, a wall
/// end or a moving wall's end) is a straight line (`straight`), met it last, and has not changed
/// course since (its last partner is cleared when it does). It needs no time, so a prediction may
/// ask it before its search.
template <class Store>
inline bool just_met(const Store& bodies, bool straight, std::uint32_t i, LastPartner partner) {
  return straight && bodies.last[i] == partner;
}

/// The same for body j (a ball or a turtle): each names the other as its last. (A body partner
/// has its own function so that the compiler sees j itself, not j unpacked from a LastPartner.)
template <class Store>
inline bool just_met_body(const Store& bodies, bool straight, std::uint32_t i, std::uint32_t j) {
  return straight && bodies.last[i] == LastPartner::of(Partner::body, j) &&
         bodies.last[j] == LastPartner::of(Partner::body, i);
}

/// "Just met, cannot meet again" does not survive a change of the wall's velocity: whether
/// `last` is a moving wall (its interior or an end) that this keyframe (`schedule.keyed`) turned.
template <class Walls, class Schedule>
inline bool keyed_partner(LastPartner last, const Walls& walls, const Schedule& schedule) {
  return !last.is_none() && ((last.kind() == Partner::moving_end && schedule.keyed[last.index() / 2]) ||
                             (last.kind() == Partner::wall && walls.mover_of[last.index()] != kNone &&
                              schedule.keyed[walls.mover_of[last.index()]]));
}

/// The principle's one test, which every prediction asks of a winning candidate: whether body
/// i's contact with `partner` at internal time t has been answered already, by the last contact
/// (just_met, mechanism 1) or by the squeeze rule (mechanism 4: BodyStore::held_against, the mark
/// squeeze.hpp leaves). The predictions whose search costs more than the test (walls, wall ends,
/// moving walls) ask its two halves apart: just_met before the search, as it needs no time, and
/// held_against after it. skip() is their disjunction, nothing more. (The halves are called
/// directly there, not through a wrapper of held_against: one more inline layer changed GCC's
/// inlining of the engine's loop and cost the gas 0.6 % more instructions for the same code.)
template <class Store>
inline bool skip(const Store& bodies, bool straight, std::uint32_t i, LastPartner partner, double t) {
  return just_met(bodies, straight, i, partner) || bodies.held_against(i, partner, t);
}

/// skip() for body j as the partner. A ball pair asks only just_met_body: a held ball that a ball
/// pushes is answered at the contact instead (push_held, squeeze.hpp), not skipped.
template <class Store>
inline bool skip_body(const Store& bodies, bool straight, std::uint32_t i, std::uint32_t j, double t) {
  return just_met_body(bodies, straight, i, j) || bodies.held_against(i, LastPartner::of(Partner::body, j), t);
}

}  // namespace turtlegas::sim::detail
