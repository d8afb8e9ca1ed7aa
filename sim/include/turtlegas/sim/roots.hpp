// SPDX-License-Identifier: MIT
#pragma once

#include <limits>

namespace turtlegas::sim {

inline constexpr double kNever = std::numeric_limits<double>::infinity();

/// The first time t >= 0 at which f(t) = c0 + c1 t + c2 t^2 goes from >= 0 to < 0 ("an approach":
/// f is a separation that contact makes zero). Returns 0 when f(0) <= 0 and f is decreasing at 0
/// (to first order, or to second order with c1 == 0 and c2 < 0): touching or overlapping by
/// round-off and approaching collides at once. A double root (a graze) is not an approach. Both
/// roots are formed without cancellation (the product-of-roots form); kNever if there is none.
/// A separation that starts <= 0 and rises without ever becoming positive falls again from its
/// maximum on: that maximum's time is returned (a contact pulled back in before it got out).
double first_approach_quadratic(double c0, double c1, double c2);

/// The same for a polynomial of degree <= 6 (coefficients c[0..degree], c[degree] may be 0),
/// searched on [0, t_max]. Roots are isolated by recursing on the derivative: between consecutive
/// critical points f is monotone, so each sign change brackets exactly one root, which is then
/// refined by safeguarded bisection to adjacent doubles. The time returned is the bracket end where
/// f >= 0, so the contact it yields never overlaps. t_max may be kNever (a root bound is used).
/// As for the quadratic, a fall that starts at or below zero is an approach from its start.
double first_approach_poly(const double* c, int degree, double t_max);

/// All real roots of the polynomial (degree <= 6) in [a, b] (finite), ascending, written to out
/// (room for `degree`). Returns their number. Each is refined to adjacent doubles.
int real_roots_in(const double* c, int degree, double a, double b, double* out);

}  // namespace turtlegas::sim
