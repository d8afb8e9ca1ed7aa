// SPDX-License-Identifier: MIT
#pragma once

#include "turtlegas/sim/field_flight.hpp"
#include "turtlegas/sim/toi.hpp"

// Times of impact for discs on field flights (field_flight.hpp): pure functions, times relative
// to now, each the first contact in [0, horizon] or kNever. The contact rules are toi.hpp's:
// touching (or overlapping by round-off) and approaching collides at 0; touching and receding
// looks for the next contact; a graze (tangency, a double root) is not a contact; a bracketed root
// is returned at the end of its bracket where the bodies are still apart, so a contact never
// overlaps. Derivations and the proofs that no root is skipped: docs/physics.md, "Fields: the mathematics".
namespace turtlegas::sim {

/// Two discs whose relative motion is a pure rotation: equal w and equal a (equal q/m in B, any E
/// and g; the drifts cancel). r = x2 - x1, dv = v2 - v1, sigma = r1 + r2. Closed form: |r(t)|^2 -
/// sigma^2 times 1 + tan^2(w t/2) is a quadratic in T = 2 tan(w t/2)/w; its falling root gives the
/// phase by atan. The relative motion repeats every period, so if nothing happens in one period
/// nothing ever does and the horizon only cuts the answer off. w == 0 gives toi_disc_disc's times.
double toi_field_disc_disc_rotating(Vec2 r, Vec2 dv, double w, double sigma, double horizon);

/// Two discs on any field flights (a turtle is w = 0, a = 0). Dispatches to the closed forms when
/// the relative motion allows (equal w and a; both w == 0, a relative parabola; one body at rest
/// and the other without drift) and otherwise to toi_field_disc_disc_bracketed.
double toi_field_disc_disc(Vec2 r, const FieldFlight& f1, const FieldFlight& f2, double sigma, double horizon);

/// The general solver, for any two flights and a finite horizon: gap g(t) = |r(t)|^2 - sigma^2
/// searched on [0, horizon] by splitting it into pieces, each either proven free of a fall (Taylor
/// bounds from |r''| <= |a1 + w1 J v1| + |a2 + w2 J v2|, which holds for every t, with the
/// evaluation error included) or proven monotone and then refined to adjacent doubles. The horizon
/// must be finite unless both bodies gyrate (or rest) with different drifts, whose envelopes part
/// for good; a non-finite horizon otherwise returns kNever.
double toi_field_disc_disc_bracketed(Vec2 r, const FieldFlight& f1, const FieldFlight& f2, double sigma,
                                     double horizon);

/// One bounded-cost search of toi_field_disc_disc_bracketed: `t` the first contact (kNever: none
/// found) and `reached`, the time up to which [0, reached] is proven free of a contact. A search
/// that needed more than a few thousand splits stops with t = kNever and reached < horizon (and
/// reached > 0: each call makes progress); continuing from `reached` (flights re-centred there)
/// finds what lies beyond. toi_field_disc_disc_bracketed does exactly that, up to 64 searches
/// (about 2.6e5 splits; before, it decided every piece on its ends after 4000 splits); past them
/// it answers kNever. The engine keeps its horizons far below that (2^30 periods at most).
struct PartialToi {
  double t = kNever;
  double reached = 0.0;
};
PartialToi toi_field_disc_disc_partial(Vec2 r, const FieldFlight& f1, const FieldFlight& f2, double sigma,
                                       double horizon);

/// A disc at rel = x - s.p1 on flight f touching the interior of segment s (either face; the foot
/// of the contact on the segment, ends included). The signed distance n.x(t) is a constant plus
/// a drift term (n.u_d) t plus a sinusoid: without normal drift (cross(n, a) == 0) each face's
/// falls come in closed form once per period, the foot of each checked and stepped along by the
/// tangential drift per period in closed form; with normal drift the distance's critical points
/// are in closed form, and each monotone piece between them is refined, searched only while the
/// circle can reach a face's contact segment. w == 0 is toi_disc_segment. horizon may be kNever.
/// Cost grows with the periods during which the circle keeps crossing the wall's line beside the
/// segment: pass the best candidate found so far (a wall end's contact) as the horizon.
double toi_field_disc_segment(Vec2 rel, const FieldFlight& f, const Segment& s, double radius, double horizon);

/// A disc at rel = x - p on flight f reaching the point p (a wall end). Without drift (a == 0) the
/// closed form of toi_field_disc_disc_rotating; w == 0 is toi_disc_point_accel; otherwise the
/// bracketed solver, searching only while the circle can reach the point. horizon may be kNever.
double toi_field_disc_point(Vec2 rel, const FieldFlight& f, double radius, double horizon);

/// The first time in [0, horizon] the coordinate x + (x(t) - x(0)) along `axis` (0: x, 1: y)
/// leaves [lo, hi], and which side (AxisExit of toi.hpp). Without drift along the axis a closed
/// form per side, else the monotone pieces between the closed-form critical points, bisected.
AxisExit field_axis_exit(double x, const FieldFlight& f, int axis, double lo, double hi, double horizon);

/// Where a drift-free circle (f.w != 0, f.a == 0) at x leaves the box [lo, hi]: field_axis_exit of
/// both axes and the earlier of the two (x first at a tie), with one arctangent instead of four.
struct BoxExit {
  double t = kNever;
  int axis = 0;        ///< 0: x, 1: y
  bool upper = false;  ///< through hi (else lo)
};
BoxExit field_box_exit_drift_free(Vec2 x, const FieldFlight& f, Vec2 lo, Vec2 hi);

/// Where a body can be: for w != 0 its centre is, at every t >= 0, exactly `rho` (the gyration
/// radius) from centre + drift t (the guiding centre), so its disc lies inside the disc of
/// `radius` = rho + `body` about it. `margin` bounds the rounding of centre and radii (the
/// quiet_time functions add it). A body at rest with no field (w == 0, a == 0, v == 0) is its own
/// envelope (rho = 0). Otherwise `bounded` is false. Needs a finite rho (below 1e150).
struct Envelope {
  Vec2 centre;
  Vec2 drift;
  double radius = 0.0;
  double rho = 0.0;
  double body = 0.0;
  double margin = 0.0;
  bool bounded = false;
};
Envelope flight_envelope(Vec2 x, const FieldFlight& f, double radius);

/// The time (>= 0, kNever when it never happens) until which the envelope provably stays inside
/// the box [lo, hi], away from a segment, from a point, or from another envelope: no event of
/// that kind can happen before it, so the engine may predict nothing for it until then. 0 when
/// nothing can be proven (unbounded envelope, or already touching). A tiny circle in a cell gets
/// kNever from all of them and costs nothing more, instead of a re-prediction every period.
double quiet_time_box(const Envelope& e, Vec2 lo, Vec2 hi);
double quiet_time_segment(const Envelope& e, const Segment& s);
double quiet_time_point(const Envelope& e, Vec2 p);
double quiet_time_pair(const Envelope& e1, const Envelope& e2);

}  // namespace turtlegas::sim
