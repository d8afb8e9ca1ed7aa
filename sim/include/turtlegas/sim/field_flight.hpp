// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>

#include "turtlegas/sim/roots.hpp"
#include "turtlegas/sim/vec2.hpp"

// Free flight of a charged disc under uniform fields, exact: pure, stateless functions of the time
// t (seconds, >= 0) since "now". Convention (docs/physics.md, "Fields: the mathematics"):
//
//   dv/dt = a + w (v.y, -v.x),   a = g + (q/m) E,   w = q Bz / m,
//
// so the velocity turns by the angle -w t: a positive charge in Bz > 0 (out of the plane) circles
// clockwise. w == 0 is today's parabola (or straight line); a small w is never treated as zero.
namespace turtlegas::sim {

/// A body's motion from "now" (its position is carried separately, relative to whatever the caller
/// measures against, so that nothing large is added to anything small).
struct FieldFlight {
  Vec2 v;           ///< velocity now, units/s
  Vec2 a;           ///< acceleration g + (q/m) E, units/s^2 (the same for the whole flight)
  double w = 0.0;   ///< W = q Bz / m, rad/s; > 0 turns clockwise
};

/// Position and velocity.
struct FieldState {
  Vec2 x;
  Vec2 v;
};

/// J(v) = (v.y, -v.x): v turned by -90 degrees, the direction the magnetic term pushes (dv/dt has
/// w J(v)). J(J(v)) = -v, perp(J(v)) = v, |J(v)| = |v|, u.J(v) = cross(u, v).
constexpr Vec2 turn_cw(Vec2 v) { return {v.y, -v.x}; }

/// The flight's coefficients at t, with theta = w t:
///   x(t) - x(0) = s v + c J(v) + ca a + da J(a),
///   v(t)        = cos_theta v + sin_theta J(v) + s a + c J(a),
/// where s = sin(theta)/w, c = (1 - cos theta)/w, ca = (1 - cos theta)/w^2, da = (theta - sin theta)/w^2.
/// Each is formed as t, t^2 or t^3 times a function of theta that tends to a constant as theta -> 0
/// (sin(theta)/theta, (1 - cos theta)/theta^2 = (sin(theta/2)/(theta/2))^2/2 and
/// (theta - sin theta)/theta^3, the last by its series for |theta| < 2), so none of them cancels
/// and w -> 0 gives s = t, c = 0, ca = t^2/2, da = 0, the parabola, continuously.
struct FlightCoefficients {
  double cos_theta = 1.0;
  double sin_theta = 0.0;
  double s = 0.0;
  double c = 0.0;
  double ca = 0.0;
  double da = 0.0;
};
FlightCoefficients flight_coefficients(double w, double t);

/// x(t) - x(0). Error: a few ulps of the sum of the four terms' magnitudes, plus the phase error
/// of theta = w t (half an ulp of theta, so |v| t eps): after 10^4 periods about 1e-11 of the radius.
Vec2 field_displacement(const FieldFlight& f, double t);
/// v(t).
Vec2 field_velocity(const FieldFlight& f, double t);
/// x(t) and v(t) from x(0) = x.
FieldState field_advance(Vec2 x, const FieldFlight& f, double t);
/// field_advance for a drift-free circle (a == 0, w != 0), to the same bits: the same
/// expressions without the acceleration's terms (which are zeros there), and without the series
/// for (theta - sin theta) / theta^3 that only they need. Inline: a charged gas in B re-forms a
/// state at every cell crossing and for every neighbour it predicts against.
inline FieldState circle_advance(Vec2 x, Vec2 v, double w, double t) {
  const double theta = w * t;
  const double h = 0.5 * theta;
  const double sh = std::sin(h), ch = std::cos(h);
  const double sinc_h = h == 0.0 ? 1.0 : sh / h;
  const double f2 = 0.5 * sinc_h * sinc_h;
  const double s = t * (sinc_h * ch);
  const double c = t * (theta * f2);
  const double cos_theta = 1.0 - 2.0 * sh * sh;
  const double sin_theta = 2.0 * sh * ch;
  const Vec2 jv = turn_cw(v);
  return {x + (s * v + c * jv), cos_theta * v + sin_theta * jv};
}
/// The acceleration now, a + w J(v). Its magnitude is the same all along the flight (the
/// magnetic term turns it with the velocity), so it bounds |x''| for every t.
constexpr Vec2 field_acceleration(const FieldFlight& f) { return f.a + f.w * turn_cw(f.v); }

/// 2 pi / |w|, seconds (kNever for w == 0).
double gyration_period(double w);
/// The velocity of the guiding centre, J(a) / w = (a.y, -a.x) / w (the E x B and g x B drifts);
/// it solves a + w J(u) = 0. Needs w != 0.
Vec2 drift_velocity(const FieldFlight& f);
/// The radius of the circle about the guiding centre, |v - drift| / |w| = |a + w J(v)| / w^2.
/// Needs w != 0.
double gyration_radius(const FieldFlight& f);
/// The guiding centre of a body at x: x - (w perp(v) - a) / w^2 (it moves at drift_velocity).
/// Needs w != 0; for a small w it is far away (the radius is large), as it should be.
Vec2 guiding_centre(Vec2 x, const FieldFlight& f);

/// The same motion seen from a frame moving at the constant velocity u: velocity v - u and, since
/// v = v' + u turns in B, the acceleration a + w J(u) (the frame's electric field E' = E + u x B,
/// times q/m). A wall translating at u under B is a fixed wall in that frame.
constexpr FieldFlight in_moving_frame(const FieldFlight& f, Vec2 u) {
  return {f.v - u, f.a + f.w * turn_cw(u), f.w};
}

/// True when the relative motion of two bodies is a straight line (both w == 0 and equal a): only
/// then can a pair that has just collided be skipped until one of them has another event. Under
/// any B, or different accelerations, two discs can meet again without anything else happening.
constexpr bool relative_motion_straight(const FieldFlight& f1, const FieldFlight& f2) {
  return f1.w == 0.0 && f2.w == 0.0 && f1.a == f2.a;
}
/// The same for a body against a fixed wall: only with no field on the body at all.
constexpr bool wall_motion_straight(const FieldFlight& f) { return f.w == 0.0 && f.a == Vec2{}; }

/// Potential energy of a ball of mass m and charge q at x in uniform g and E: -m g.x - q E.x
/// (B does no work). Kinetic plus this is conserved along every flight.
constexpr double field_potential(Vec2 x, double mass, double charge, Vec2 g, Vec2 e) {
  return -(mass * dot(g, x) + charge * dot(e, x));
}

/// Step mode's kick: the velocity's exact change over dt under a and w with the position held
/// (uniform fields do not depend on it), i.e. the rotation of v by -w dt combined with the
/// acceleration, v(dt) of field_velocity. Drift-then-kick per step (today's step mode) is first
/// order in dt; a half kick, the drift, a half kick (Strang) is second order. docs/physics.md, "Fields: the mathematics".
Vec2 field_kick(Vec2 v, Vec2 a, double w, double dt);
/// The rotation alone, R(-w dt) v (for a kick split as a dt/2, rotation, a dt/2: second order).
Vec2 rotation_kick(Vec2 v, double w, double dt);

}  // namespace turtlegas::sim
