// SPDX-License-Identifier: MIT
// Times of impact in 3-D, pure functions (docs/physics.md, "3-D"). Every flight is
// x(t) = x + v t + a t^2 / 2 (a uniform acceleration: gravity, a uniform electric field). A
// contact is a gap polynomial g(t) that goes from > 0 to < 0 (an approach); g is a quadratic for
// straight relative flights and a quartic under a relative acceleration. Under a magnetic field
// a flight is a helix (Helix3) and contacts come from conservative advancement (first_touch).
#pragma once

#include "turtlegas/sim/roots.hpp"
#include "turtlegas/sim/vec3.hpp"

namespace turtlegas::sim {

/// The approach times of g(t) = c[0] + c[1] t + ... + c[degree] t^degree (degree <= 4) in
/// [0, t_max], ascending, written to out (room for 4): roots where g falls through zero. A gap
/// that starts within -tol of zero and falls is an approach at 0 (touching by round-off). Under
/// degree 2 the roots are the cancellation-free quadratic pair; above, real_roots_in (roots.hpp)
/// brackets every sign change between consecutive critical points, so no approach is skipped
/// (a double root, a graze, is not an approach). Returns the number written.
int approach_times(const double* c, int degree, double t_max, double tol, double* out);

/// The coefficients of |d + w t + b t^2 / 2|^2 - rho^2, the gap of a point at relative
/// position d, velocity w, acceleration b against a sphere of radius rho around the origin.
void squared_gap(Vec3 d, Vec3 w, Vec3 b, double rho, double* c);

/// The first approach of two spheres, relative position d = x2 - x1, velocity w, acceleration b,
/// sum of radii sigma, in [0, t_max]; kNever if none. With b == 0 this is the memo's vector form
/// (first_approach_quadratic); otherwise the first falling root of the quartic.
double toi_sphere_sphere(Vec3 d, Vec3 w, Vec3 b, double sigma, double t_max);

/// The position at time t of a flight x, v, a.
constexpr Vec3 fly(Vec3 x, Vec3 v, Vec3 a, double t) {
  return x + t * v + (0.5 * t * t) * a;
}

/// A flight under a uniform acceleration a and a uniform magnetic field, dv/dt = a + v x omega
/// (omega = (q/m) B, docs/physics.md "3-D: magnetic fields"): along b = omega / |omega| the
/// parabola v_par t + a_par t^2 / 2; across it the drift v_d = (a_perp x omega) / |omega|^2 (E x B
/// / B^2 for a = qE/m) plus the circle of u0 = v_perp - v_d turning by -|omega| t about b.
struct Helix3 {
  Vec3 b;            ///< unit, along omega
  double w = 0.0;    ///< |omega|, radians per second (> 0)
  double v_par = 0.0, a_par = 0.0;
  Vec3 v_d, u0, bu0;  ///< the drift, the circling velocity at t = 0, b x u0
  Helix3(Vec3 v, Vec3 a, Vec3 omega);
  /// The displacement x(t) - x(0) and the velocity at t.
  Vec3 displacement(double t) const;
  Vec3 velocity(double t) const;
  /// |x''(t)|, the same at every t: sqrt(a_par^2 + w^2 |u0|^2).
  double accel() const;
};

/// The first time in [0, horizon] at which a gap g(s) (a distance minus a radius, g(0) > -tol)
/// falls to tol or below while closing, by conservative advancement: `eval(s, g, gdot)` gives g
/// and its rate, and g(s0 + h) >= g(s0) + gdot h - accel h^2 / 2 for every h >= 0 (a convex
/// distance along a flight with |x''| <= accel), so each step, the largest h that keeps this bound
/// above tol / 2, provably passes no contact. Returns kNever when none is found before the horizon;
/// `reached` is how far the search proved the gap open (the horizon, or where it stopped after
/// max_steps steps: the caller predicts again from there).
template <class Eval>
double first_touch(Eval eval, double accel, double horizon, double tol, int max_steps, double& reached) {
  double s = 0.0;
  for (int n = 0; n < max_steps; ++n) {
    double g, gd;
    eval(s, g, gd);
    if (g <= tol && gd < 0.0) {
      reached = s;
      return s;
    }
    // Above tol: keep the bound above tol / 2 (the evaluation's round-off stays far below it).
    // Touching by round-off and not closing: step off keeping it above -tol.
    const double G = g > tol ? g - 0.5 * tol : g + tol;
    double h;
    if (!(G > 0.0)) h = 0.0;
    else if (accel == 0.0) h = gd >= 0.0 ? kNever : G / -gd;
    else if (gd < 0.0) h = 2.0 * G / (-gd + std::sqrt(gd * gd + 2.0 * accel * G));  // no cancellation
    else h = (gd + std::sqrt(gd * gd + 2.0 * accel * G)) / accel;
    if (!(h > 0.0)) h = 1e-15 * (1.0 + s);  // a standing tangency: creep past it
    if (s + h >= horizon) {
      reached = horizon;
      return kNever;
    }
    s += h;
  }
  reached = s;
  return kNever;
}

}  // namespace turtlegas::sim
