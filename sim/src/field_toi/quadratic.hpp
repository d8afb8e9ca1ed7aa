// SPDX-License-Identifier: MIT
// Private to sim/src/field_toi/: the tan-half-angle quadratic, the closed form behind every
// field time of impact of a constant plus a sinusoid (discs turning about each other, a face or a
// cell side without drift across it, the critical phases of a projection).
#pragma once

#include <cmath>
#include <limits>
#include <numbers>

namespace turtlegas::sim::field_toi_detail {

inline constexpr double kEps = std::numeric_limits<double>::epsilon();
inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

// A constant plus a sinusoid of theta = w t, f = f0 + P sin(theta) + Q (1 - cos theta), times
// 1 + tau^2 (tau = tan(theta/2) > -inf) is f0 + 2 P tau + (f0 + 2 Q) tau^2: with T = 2 tau / w,
// a quadratic q(T) = c0 + 2 b T + c2 T^2 whose coefficients stay finite as w -> 0 (it tends to the
// straight-line or parabola quadratic in t, and T -> t). T runs over (-inf, inf) once per period:
// T >= 0 is the first half period (|w| t = 2 atan(|w| T / 2)), T = +-inf the middle, T < 0 the
// second half; sign(f) = sign(q) and T grows with t, so f's falls are q's falls.

// The phase |w| t in [0, 2 pi) of T = num / den (den == 0: T infinite, phase pi), for knots.
inline double phase_of(double num, double den, double aw) {
  if (den < 0.0) {
    num = -num;
    den = -den;
  }
  const double half = std::atan2(0.5 * aw * num, den);  // in [-pi/2, pi/2]
  if (half >= 0.0) return 2.0 * half + 0.0;              // + 0.0: no -0
  return kTwoPi + 2.0 * half;
}

// The time in [0, 2 pi / |w|) of T = num / den: 2 atan(|w| T / 2) / |w| in the first half period
// (T >= 0), formed as T (1 - x^2/3), x = |w| T / 2, when x < 1e-8 (the next term, x^4/5, is below
// 2e-33), so that neither an underflow of |w| num nor a tiny w can turn it into 0: a small w is
// never zero; pi / |w| for T infinite; (2 pi + 2 alpha) / |w|, alpha in [-pi/2, 0), in the second
// half, a sum of like signs.
inline double time_of(double num, double den, double aw) {
  if (den < 0.0) {
    num = -num;
    den = -den;
  }
  if (num >= 0.0 && den > 0.0) {
    const double q = num / den;
    const double x = 0.5 * aw * q;
    if (x < 1e-8) return q * (1.0 - x * x / 3.0);
    return 2.0 * std::atan(x) / aw;
  }
  if (den == 0.0) return kPi / aw;
  return (kTwoPi + 2.0 * std::atan2(0.5 * aw * num, den)) / aw;
}

// The time in [0, 2 pi / |w|) of the falling root of q (where q' = -2 sqrt(disc) < 0), disc = b^2 -
// c0 c2 given by the caller in its own cancellation-free form; -1 when q has no simple root (a miss
// or a graze). The root (-b - sqrt(disc)) / c2 is formed as c0 / (-b + sqrt(disc)) when b < 0, so
// that neither form subtracts; c2 == 0 with b > 0 puts it at infinity (half a period).
inline double falling_time(double c0, double b, double c2, double disc, double aw) {
  if (!(disc > 0.0)) return -1.0;
  const double sq = std::sqrt(disc);
  if (b < 0.0) return time_of(c0, sq - b, aw);
  return time_of(-(b + sq), c2, aw);
}

}  // namespace turtlegas::sim::field_toi_detail
