// SPDX-License-Identifier: MIT
// Times of impact in 3-D, pure functions (docs/physics.md, "3-D"). Every flight is
// x(t) = x + v t + a t^2 / 2 (a uniform acceleration: gravity, a uniform electric field). A
// contact is a gap polynomial g(t) that goes from > 0 to < 0 (an approach); g is a quadratic for
// straight relative flights and a quartic under a relative acceleration.
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

}  // namespace turtlegas::sim
