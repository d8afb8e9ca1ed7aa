// SPDX-License-Identifier: MIT
#include "turtlegas/sim/toi3.hpp"

#include <algorithm>
#include <cmath>

#include "turtlegas/sim/roots.hpp"

namespace turtlegas::sim {
namespace {

double derivative_at(const double* c, int degree, double t) {
  double d = 0.0;
  for (int k = degree; k >= 1; --k) d = d * t + k * c[k];
  return d;
}

// Both real roots of c0 + c1 t + c2 t^2, each formed without cancellation (q / c2 and c0 / q,
// q = -(c1 + sign(c1) sqrt(disc)) / 2: the terms added have the same sign).
int quadratic_roots(double c0, double c1, double c2, double* out) {
  if (c2 == 0.0) {
    if (c1 == 0.0) return 0;
    out[0] = -c0 / c1;
    return 1;
  }
  const double disc = c1 * c1 - 4.0 * c2 * c0;
  if (!(disc > 0.0)) return 0;  // none, or a double root (a graze)
  const double q = -0.5 * (c1 + std::copysign(std::sqrt(disc), c1));
  int n = 0;
  out[n++] = q / c2;
  if (q != 0.0) out[n++] = c0 / q;
  if (n == 2 && out[1] < out[0]) std::swap(out[0], out[1]);
  return n;
}

}  // namespace

int approach_times(const double* c, int degree, double t_max, double tol, double* out) {
  while (degree > 0 && c[degree] == 0.0) --degree;
  int n = 0;
  // Touching by round-off (within tol) and closing: an approach now.
  if (c[0] <= 0.0 && c[0] >= -tol && degree >= 1 && derivative_at(c, degree, 0.0) < 0.0) out[n++] = 0.0;
  if (degree == 0) return n;
  double roots[4];
  int m = 0;
  if (degree <= 2) {
    m = quadratic_roots(c[0], c[1], degree == 2 ? c[2] : 0.0, roots);
  } else {
    if (!std::isfinite(t_max)) {
      // Cauchy's bound on the roots' size closes the interval real_roots_in searches.
      double big = 0.0;
      for (int k = 0; k < degree; ++k) big = std::max(big, std::abs(c[k] / c[degree]));
      t_max = 1.0 + big;
    }
    m = real_roots_in(c, degree, 0.0, t_max, roots);
  }
  for (int k = 0; k < m; ++k) {
    const double t = roots[k];
    if (!(t > 0.0) || t > t_max) continue;
    if (derivative_at(c, degree, t) < 0.0) out[n++] = t;
  }
  return n;
}

void squared_gap(Vec3 d, Vec3 w, Vec3 b, double rho, double* c) {
  c[0] = norm2(d) - rho * rho;
  c[1] = 2.0 * dot(d, w);
  c[2] = norm2(w) + dot(d, b);
  c[3] = dot(w, b);
  c[4] = 0.25 * norm2(b);
}

Helix3::Helix3(Vec3 v, Vec3 a, Vec3 omega) {
  w = norm(omega);
  b = (1.0 / w) * omega;
  v_par = dot(v, b);
  a_par = dot(a, b);
  const Vec3 a_perp = a - a_par * b;
  v_d = (1.0 / (w * w)) * cross(a_perp, omega);
  u0 = v - v_par * b - v_d;
  bu0 = cross(b, u0);
}

Vec3 Helix3::displacement(double t) const {
  // 1 - cos(w t) as 2 sin^2(w t / 2): no cancellation at small angles.
  const double sh = std::sin(0.5 * w * t);
  return (v_par * t + 0.5 * a_par * t * t) * b + t * v_d + (std::sin(w * t) / w) * u0 - (2.0 * sh * sh / w) * bu0;
}

Vec3 Helix3::velocity(double t) const {
  return (v_par + a_par * t) * b + v_d + std::cos(w * t) * u0 - std::sin(w * t) * bu0;
}

double Helix3::accel() const { return std::sqrt(a_par * a_par + w * w * norm2(u0)); }

double toi_sphere_sphere(Vec3 d, Vec3 w, Vec3 b, double sigma, double t_max) {
  if (b.x == 0.0 && b.y == 0.0 && b.z == 0.0) {
    const double dw = dot(d, w);
    if (dw >= 0.0) return kNever;  // receding (or at rest relative): a straight pair never meets
    const double t = first_approach_quadratic(norm2(d) - sigma * sigma, 2.0 * dw, norm2(w));
    return t <= t_max ? t : kNever;
  }
  double c[5];
  squared_gap(d, w, b, sigma, c);
  double times[4];
  const int n = approach_times(c, 4, t_max, 1e-9 * sigma * sigma, times);
  return n > 0 ? times[0] : kNever;
}

}  // namespace turtlegas::sim
