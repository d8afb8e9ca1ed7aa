// SPDX-License-Identifier: MIT
#include "turtlegas/sim/roots.hpp"

#include <algorithm>
#include <cmath>

namespace turtlegas::sim {
namespace {

constexpr int kMaxDegree = 6;

double eval(const double* c, int degree, double t) {
  double f = c[degree];
  for (int k = degree - 1; k >= 0; --k) f = f * t + c[k];
  return f;
}

int effective_degree(const double* c, int degree) {
  while (degree > 0 && c[degree] == 0.0) --degree;
  return degree;
}

// Fujiwara's bound: every root t satisfies |t| <= 2 max |c_{n-k}/c_n|^(1/k).
double root_bound(const double* c, int degree) {
  double bound = 0.0;
  for (int k = 1; k <= degree; ++k) {
    const double ratio = std::abs(c[degree - k] / c[degree]);
    const double term = k == degree ? std::pow(ratio / 2.0, 1.0 / k) : std::pow(ratio, 1.0 / k);
    bound = std::max(bound, term);
  }
  return 2.0 * bound;
}

// f has exactly one sign change on [lo, hi] (f(lo) and f(hi) of opposite signs, f monotone).
// Returns the pair of adjacent doubles bracketing the root, as (point with sign of f(lo), other).
struct Bracket {
  double keep;   // end with the sign of f(lo)
  double other;  // end with the sign of f(hi)
};

Bracket refine(const double* c, int degree, double lo, double hi) {
  double flo = eval(c, degree, lo);
  for (int it = 0; it < 200; ++it) {
    const double mid = lo + 0.5 * (hi - lo);
    if (mid <= lo || mid >= hi) break;
    const double fm = eval(c, degree, mid);
    if (fm == 0.0) return {mid, mid};
    if ((fm > 0.0) == (flo > 0.0)) {
      lo = mid;
      flo = fm;
    } else {
      hi = mid;
    }
  }
  return {lo, hi};
}

void derivative(const double* c, int degree, double* d) {
  for (int k = 1; k <= degree; ++k) d[k - 1] = k * c[k];
}

// Critical points of f in (a, b), ascending; returns their count.
int critical_points(const double* c, int degree, double a, double b, double* out) {
  if (degree < 2) return 0;
  double d[kMaxDegree];
  derivative(c, degree, d);
  double roots[kMaxDegree];
  const int n = real_roots_in(d, degree - 1, a, b, roots);
  int m = 0;
  for (int k = 0; k < n; ++k)
    if (roots[k] > a && roots[k] < b) out[m++] = roots[k];
  return m;
}

}  // namespace

double first_approach_quadratic(double c0, double c1, double c2) {
  if (c0 <= 0.0 && (c1 < 0.0 || (c1 == 0.0 && c2 < 0.0))) return 0.0;
  if (c2 == 0.0) {
    if (c1 >= 0.0) return kNever;
    return -c0 / c1;  // c0 > 0 here
  }
  const double disc = c1 * c1 - 4.0 * c2 * c0;
  // Inside (c0 <= 0), receding (c1 > 0) but pulled back (c2 < 0), and never out (its maximum
  // -disc / (4 c2) is <= 0): it approaches from the turning point on, deeper at once. The contact
  // is there, not "never" (a disc a few ulps inside a slope once sank into it under gravity).
  if (c0 <= 0.0 && c1 > 0.0 && c2 < 0.0 && !(disc > 0.0)) return c1 / (-2.0 * c2);
  if (!(disc > 0.0)) return kNever;  // no real root, or a double root (a graze)
  const double sq = std::sqrt(disc);
  // f'(t) = c1 + 2 c2 t equals -sq at the root (-c1 - sq) / (2 c2): that one is the approach.
  // Write it as q / c2 or c0 / q, whichever adds quantities of the same sign.
  const double q = -0.5 * (c1 + std::copysign(sq, c1));
  const double t = c1 >= 0.0 ? q / c2 : c0 / q;
  return t >= 0.0 ? t : kNever;
}

int real_roots_in(const double* c, int degree, double a, double b, double* out) {
  degree = effective_degree(c, degree);
  if (degree == 0 || !(a <= b)) return 0;
  if (degree == 1) {
    const double t = -c[0] / c[1];
    if (t >= a && t <= b) {
      out[0] = t;
      return 1;
    }
    return 0;
  }
  double crit[kMaxDegree];
  const int nc = critical_points(c, degree, a, b, crit);
  double knots[kMaxDegree + 2];
  int nk = 0;
  knots[nk++] = a;
  for (int k = 0; k < nc; ++k) knots[nk++] = crit[k];
  knots[nk++] = b;
  int n = 0;
  double fprev = eval(c, degree, knots[0]);
  if (fprev == 0.0) out[n++] = knots[0];
  for (int k = 1; k < nk; ++k) {
    const double fk = eval(c, degree, knots[k]);
    if (fk == 0.0) {
      if (n == 0 || out[n - 1] != knots[k]) out[n++] = knots[k];
    } else if (fprev != 0.0 && (fk > 0.0) != (fprev > 0.0)) {
      const Bracket br = refine(c, degree, knots[k - 1], knots[k]);
      out[n++] = 0.5 * (br.keep + br.other);
    }
    fprev = fk;
  }
  return n;
}

double first_approach_poly(const double* c, int degree, double t_max) {
  degree = effective_degree(c, degree);
  if (degree <= 2) {
    const double t = first_approach_quadratic(c[0], degree >= 1 ? c[1] : 0.0,
                                              degree >= 2 ? c[2] : 0.0);
    return t <= t_max ? t : kNever;
  }
  double d[kMaxDegree];
  derivative(c, degree, d);
  const double f0 = c[0];
  if (f0 <= 0.0 && (d[0] < 0.0 || (d[0] == 0.0 && d[1] < 0.0))) return 0.0;
  double hi = std::min(t_max, root_bound(c, degree));
  if (!(hi > 0.0)) return kNever;
  double crit[kMaxDegree];
  const int nc = critical_points(c, degree, 0.0, hi, crit);
  double lo = 0.0;
  double flo = f0;
  for (int k = 0; k <= nc; ++k) {
    const double end = k < nc ? crit[k] : hi;
    const double fend = eval(c, degree, end);
    // f is monotone on [lo, end]; an approach is a fall from >= 0 to < 0, or any fall that
    // starts inside (flo <= 0: a disc that rose without getting out, and now sinks again).
    if (flo <= 0.0 && fend < flo) return lo;
    if (flo >= 0.0 && fend < 0.0) {
      if (flo == 0.0) return lo;
      const Bracket br = refine(c, degree, lo, end);
      return br.keep;
    }
    lo = end;
    flo = fend;
  }
  return kNever;
}

}  // namespace turtlegas::sim
