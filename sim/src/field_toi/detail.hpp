// SPDX-License-Identifier: MIT
// Private to sim/src/field_toi/: the machinery the searches share. A flight at rest; the
// bracketed refinement of a fall; one coordinate's projection p(t) = n.(x(t) - x(0)), its critical
// phases, and the search of its gaps' first fall piece by piece, inside the windows where a
// drifting circle can reach them.
#pragma once

#include <algorithm>
#include <cmath>

#include "quadratic.hpp"
#include "turtlegas/sim/field_toi.hpp"

namespace turtlegas::sim::field_toi_detail {

inline bool at_rest(const FieldFlight& f) { return f.w == 0.0 && f.a == Vec2{} && f.v == Vec2{}; }

// ---- Bracketed refinement ------------------------------------------------------------------
// gap(lo) >= 0 > gap(hi). Shrinks the bracket to adjacent doubles (or 400 steps) and returns lo,
// where the bodies are apart.
// gap_d(t) returns {g, g'} (one evaluation of the flight gives both). Newton from the end nearer
// the root, its step lengthened by a thousandth and four ulps so that the iterate lands just beyond
// the root and the bracket's far end closes in too (the bracket, not the iterate, is the answer);
// a midpoint whenever the step would leave the bracket or is not at most half the previous one
// (Numerical Recipes' rtsafe rule), and once the bracket is 64 ulps wide, where the values are
// round-off. So it converges quadratically where Newton does and never slower than bisection.
struct GapD {
  double g, d;
};
template <class GapDeriv>
double refine_fall_newton(const GapDeriv& gap_d, double lo, GapD vlo, double hi, GapD vhi) {
  double last_step = hi - lo;
  for (int it = 0; it < 400; ++it) {
    const double next = std::nextafter(lo, hi);
    if (!(next < hi)) break;  // adjacent doubles
    double m = lo + 0.5 * (hi - lo);
    const bool fine = hi - lo <= 64.0 * kEps * std::max(std::abs(lo), std::abs(hi));
    if (!fine) {
      const bool from_lo = vlo.g <= -vhi.g;
      const double x = from_lo ? lo : hi;
      const GapD vx = from_lo ? vlo : vhi;
      const double step = -vx.g / vx.d;
      const double cand = x + (step + 1e-3 * step) + (from_lo ? 4.0 : -4.0) * kEps * std::abs(x);
      if (cand > lo && cand < hi && std::abs(step) <= 0.5 * last_step) {
        m = cand;
        last_step = std::abs(step);
      } else {
        last_step = 0.5 * (hi - lo);
      }
    }
    if (!(m > lo)) m = next;
    if (!(m < hi)) m = std::nextafter(hi, lo);
    const GapD vm = gap_d(m);
    if (vm.g == 0.0) return m;  // touching: apart, and the root to round-off
    if (vm.g > 0.0) {
      lo = m;
      vlo = vm;
    } else {
      hi = m;
      vhi = vm;
    }
  }
  return lo;
}

// ---- One coordinate: p(t) = n.(x(t) - x(0)) ------------------------------------------------
// p = s A + c B + ca C + da D with A = n.v, B = cross(n, v), C = n.a, D = cross(n, a); its rate
// n.v(t) = cos A + sin B + s C + c D. D = w (n.u_d) is the drift across n: without it p is a
// constant plus a sinusoid, with it a sinusoid plus (n.u_d) t.
struct Projection {
  double w, A, B, C, D, acc_n;  // acc_n = n.(a + w J v), n.x''(0)
  Projection(const FieldFlight& f, Vec2 n)
      : w(f.w), A(dot(n, f.v)), B(cross(n, f.v)), C(dot(n, f.a)), D(cross(n, f.a)),
        acc_n(dot(n, field_acceleration(f))) {}
  double value(double t) const {
    const FlightCoefficients k = flight_coefficients(w, t);
    return k.s * A + k.c * B + k.ca * C + k.da * D;
  }
  // {p(t), p'(t)}.
  GapD eval(double t) const {
    const FlightCoefficients k = flight_coefficients(w, t);
    return {k.s * A + k.c * B + k.ca * C + k.da * D, k.cos_theta * A + k.sin_theta * B + k.s * C + k.c * D};
  }
};

// The phases in [0, 2 pi) at which the rate n.v(t) vanishes, ascending (at most 2): the rate times
// 1 + tau^2 is the quadratic A + (n.x''(0)) T + w (D/2 - w A/4) T^2 in T (derived as above).
inline int critical_phases(const Projection& p, double* out) {
  const double aw = std::abs(p.w);
  const double c0 = p.A, c1 = p.acc_n, c2 = p.w * (0.5 * p.D - 0.25 * p.w * p.A);
  int n = 0;
  if (c2 == 0.0) {
    if (c1 != 0.0) {
      out[n++] = phase_of(-c0, c1, aw);
      out[n++] = kPi;  // the second root at T = infinity
    }
  } else {
    const double disc = c1 * c1 - 4.0 * c2 * c0;
    if (disc >= 0.0) {
      const double q = -0.5 * (c1 + std::copysign(std::sqrt(disc), c1));
      if (q != 0.0) {
        out[n++] = phase_of(q, c2, aw);
        out[n++] = phase_of(c0, q, aw);
      } else {
        out[n++] = 0.0;  // c1 == 0 == c0: a double root at T = 0
      }
    }
  }
  if (n == 2 && out[1] < out[0]) std::swap(out[0], out[1]);
  return n;
}

// A gap of one coordinate: g0 + sign p(t) (>= 0 apart).
struct Gap1 {
  double g0;
  double sign;
};

// The first time in [t_begin, t_end] (t_end finite) at which one of the gaps falls from >= 0 to < 0
// with accept(t); *which = its index. The pieces between consecutive critical times are monotone
// in p, so in each piece each gap changes sign at most once, and only a gap whose sign * rate is
// negative there can fall: an end-point sign test finds every fall and refine_fall brackets it.
template <class Accept>
double first_fall_pieces(const Projection& p, const Gap1* gaps, int ngaps, double t_begin, double t_end,
                         const Accept& accept, int* which) {
  const double aw = std::abs(p.w);
  double phases[2];
  const int np = critical_phases(p, phases);
  double k = std::floor(t_begin * aw / kTwoPi) - 1.0;  // period index of the next critical time
  int j = 0;
  double t0 = t_begin;
  GapD p0 = p.eval(t0);
  while (t0 < t_end) {
    double t1 = t_end;
    // The next critical time after t0: the phases' times grow by a period every np turns, so the
    // search ends.
    for (bool found = np == 0; !found;) {
      const double tc = (phases[j] + kTwoPi * k) / aw;
      if (++j == np) {
        j = 0;
        k += 1.0;
      }
      if (tc > t0) {
        t1 = std::min(tc, t_end);
        found = true;
      }
    }
    const GapD p1 = p.eval(t1);
    for (int g = 0; g < ngaps; ++g) {
      const Gap1 gap = gaps[g];
      const GapD gl{gap.g0 + gap.sign * p0.g, gap.sign * p0.d}, gr{gap.g0 + gap.sign * p1.g, gap.sign * p1.d};
      if (!(gl.g >= 0.0 && gr.g < 0.0)) continue;
      auto gap_d = [&](double s) {
        const GapD v = p.eval(s);
        return GapD{gap.g0 + gap.sign * v.g, gap.sign * v.d};
      };
      const double t = refine_fall_newton(gap_d, t0, gl, t1, gr);
      if (accept(t)) {
        *which = g;
        return t;
      }
    }
    t0 = t1;
    p0 = p1;
  }
  return kNever;
}

// The times at which each gap can vanish: p(t) = pg0 + (n.u_d) t + (a sinusoid of amplitude <=
// radius), pg0 = n.x''(0) / w^2 the guiding centre's offset, so gap g can be zero only while
// |g0 + sign (pg0 + (n.u_d) t)| <= radius: one interval per gap, widened by the rounding of these
// quantities and by two periods. Outside them every gap keeps its sign, so the pieces need only be
// searched inside (a tiny circle drifting slowly towards a wall then costs a few periods, not all
// the periods of its approach). Returns the number of disjoint intervals (<= ngaps), ascending,
// clipped to [t_begin, t_end]; without drift across n, the whole of [t_begin, t_end].
struct Window {
  double begin = 0.0;
  double end = kNever;
};
inline int reach_windows(const Projection& p, double rho, const Gap1* gaps, int ngaps, double t_begin, double t_end,
                  Window* out) {
  const double rate = p.D / p.w;  // n.u_d
  if (rate == 0.0) {
    out[0] = {t_begin, t_end};
    return t_begin < t_end ? 1 : 0;
  }
  const double pg0 = p.acc_n / (p.w * p.w);
  const double two_periods = 2.0 * gyration_period(p.w);
  int n = 0;
  for (int g = 0; g < ngaps; ++g) {
    const double l0 = gaps[g].g0 + gaps[g].sign * pg0;
    const double reach = rho + 64.0 * kEps * (std::abs(gaps[g].g0) + std::abs(pg0) + rho);
    const double r = gaps[g].sign * rate;
    double t1 = (-reach - l0) / r, t2 = (reach - l0) / r;
    if (t1 > t2) std::swap(t1, t2);
    const Window w{std::max(t1 - two_periods, t_begin), std::min(t2 + two_periods, t_end)};
    if (w.begin < w.end) out[n++] = w;
  }
  for (int a = 1; a < n; ++a)  // n <= 2: an insertion sort
    for (int b = a; b > 0 && out[b].begin < out[b - 1].begin; --b) std::swap(out[b], out[b - 1]);
  int m = 0;
  for (int k = 0; k < n; ++k) {
    if (m > 0 && out[k].begin <= out[m - 1].end) {
      out[m - 1].end = std::max(out[m - 1].end, out[k].end);
    } else {
      out[m++] = out[k];
    }
  }
  return m;
}

// first_fall_pieces over the reach windows in turn. relevant(ta, tb) (true if in doubt) may rule
// out stretches of many periods at once: a window is split in halves, left first, down to four
// periods, and only stretches it cannot rule out are searched piece by piece.
template <class Accept, class Relevant>
double first_fall_windows(const Projection& p, double rho, const Gap1* gaps, int ngaps, double t_end,
                          const Accept& accept, const Relevant& relevant, int* which) {
  Window win[4];
  const int nw = reach_windows(p, rho, gaps, ngaps, 0.0, t_end, win);
  const double chunk = 4.0 * gyration_period(p.w);
  for (int k = 0; k < nw; ++k) {
    if (!std::isfinite(win[k].end)) return kNever;  // callers pass a finite horizon with drift
    Window stack[128];
    int top = 0;
    stack[top++] = win[k];
    while (top > 0) {
      const Window c = stack[--top];
      if (!relevant(c.begin, c.end)) continue;
      if (c.end - c.begin <= chunk || top + 2 > 128) {
        const double t = first_fall_pieces(p, gaps, ngaps, c.begin, c.end, accept, which);
        if (t != kNever) return t;
        continue;
      }
      const double mid = c.begin + 0.5 * (c.end - c.begin);
      stack[top++] = {mid, c.end};
      stack[top++] = {c.begin, mid};
    }
  }
  return kNever;
}

}  // namespace turtlegas::sim::field_toi_detail
