// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>

#include "turtlegas/sim/roots.hpp"
#include "turtlegas/sim/vec2.hpp"

// Times of impact and collision responses: pure functions, the memo's vector formulas written in
// cancellation-free arrangements. Every time returned is relative to "now" (seconds >= 0) or kNever.
// See docs/physics.md for the derivations.
namespace turtlegas::sim {

/// A wall segment in the form the engine uses: first end p1, unit tangent u (towards the second
/// end), unit normal n = perp(u), length len.
struct Segment {
  Vec2 p1;
  Vec2 u;
  Vec2 n;
  double len = 0.0;
};

Segment make_segment(Vec2 from, Vec2 to);

/// Two discs whose centres separate by r + v t (r = x2 - x1, v = v2 - v1): when their distance
/// first falls to sigma = r1 + r2. Memo: t = -(x.v + sqrt(r^2 v^2 - (x cross v)^2)) / v^2; written
/// as (|r|^2 - sigma^2) / (-x.v + sqrt(...)) so that nothing cancels as the discs near contact.
/// Inline: it is the engine's innermost loop.
inline double toi_disc_disc(Vec2 r, Vec2 v, double sigma) {
  const double b = dot(r, v);
  const double gap = norm2(r) - sigma * sigma;
  if (gap <= 0.0) return b < 0.0 ? 0.0 : kNever;  // touching: approach collides now, recession never
  if (b >= 0.0) return kNever;
  const double v2 = norm2(v);
  const double c = cross(r, v);
  // The memo's radicand sigma^2 v^2 - (r x v)^2 equals b^2 - v^2 gap, without the cancellation of b^2
  // against v^2 |r|^2 for discs far apart.
  const double disc = sigma * sigma * v2 - c * c;
  if (!(disc > 0.0)) return kNever;  // a miss, or a graze
  return gap / (-b + std::sqrt(disc));
}

/// A disc of radius `radius` at rel = x - end moving with v reaching a point (a wall end).
inline double toi_disc_point(Vec2 rel, Vec2 v, double radius) { return toi_disc_disc(rel, v, radius); }

/// A disc with centre at rel = x - s.p1 moving with v and constant acceleration a, touching the
/// interior of segment s (contact foot on the segment, ends included).
double toi_disc_segment(Vec2 rel, Vec2 v, Vec2 a, const Segment& s, double radius);

/// A disc touching the interior of a segment whose two ends move in straight lines at constant
/// velocities, so that it translates, turns and stretches at once (a wall between keyframes). In
/// the frame of the segment's first end the disc's centre is at rel + v t + a t^2/2 and the second
/// end at d0 + w t. Returns the first time in [0, t_max] (t_max finite) at which the disc's
/// distance to the segment's line falls to `radius` with the contact foot on the segment (ends
/// included), or kNever. Root finding, bracketed: the distance minus the radius changes sign only
/// at real roots of the polynomial cross(D, Y)^2 - radius^2 |D|^2 (degree <= 6), which are isolated
/// exactly; the fall between two of them is then bisected on the distance itself to adjacent
/// doubles, and the end where the disc has not yet reached the wall is returned. Touching and
/// approaching at t = 0 returns 0; a graze is not a contact. w == 0 gives the same times as
/// toi_disc_segment to round-off (the engine uses that closed form for pure translation).
/// Also a contact: touching at rate 0 while the line closes at second order, and the foot coming
/// onto the segment over an end at the contact distance (a disc touching the pivot of a turning
/// arm: there the wall's point does not move, so the contact has neither an approach speed nor a
/// gap to close; docs/physics.md, "Walls that move in time").
double toi_disc_deforming_segment(Vec2 rel, Vec2 v, Vec2 a, Vec2 d0, Vec2 w, double radius, double t_max);

/// The second derivative at t = 0 of the signed distance cross(D, Y) / |D| from the centre
/// Y = rel + v t + a t^2/2 to the line of D = d0 + w t (both in the frame of the first end): how
/// hard a turning or stretching wall presses a disc touching it, field included (positive along
/// perp(d0)).
double deforming_line_accel(Vec2 rel, Vec2 v, Vec2 a, Vec2 d0, Vec2 w);

/// A disc under constant acceleration a reaching a point: the quartic |rel + v t + a t^2/2| = radius,
/// searched on [0, t_max] (a == 0 falls back to the closed form).
double toi_disc_point_accel(Vec2 rel, Vec2 v, Vec2 a, double radius, double t_max);

/// The first time x + v t + a t^2/2 leaves [lo, hi] along one axis; `upper` says which side.
struct AxisExit {
  double t = kNever;
  bool upper = false;
};
AxisExit axis_exit(double x, double v, double a, double lo, double hi);

/// Collision responses. e is the restitution: the memo's "2 replaced by 1 + e".
/// Ball-ball: F = x2 - x1 at contact; changes v1 and v2, conserving momentum.
void respond_disc_disc(Vec2& v1, Vec2& v2, double m1, double m2, Vec2 F, double e);
/// Ball-wall: n is a unit normal of the wall (either side): v' = v - (1+e)(v.n) n.
Vec2 respond_wall(Vec2 v, Vec2 n, double e);
/// Ball-wall-end: F = x - end at contact: v' = v - (1+e)(v.F/|F|^2) F.
Vec2 respond_point(Vec2 v, Vec2 F, double e);

}  // namespace turtlegas::sim
