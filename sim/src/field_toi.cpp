// SPDX-License-Identifier: MIT
// Times of impact of field flights (field_toi.hpp). Over 600 lines on purpose: the pair, face, end
// and cell-exit searches share file-local machinery (gap projections, critical phases, the
// isolation of monotone pieces, the bracketed search and its continuation) that no other file
// should see; split, it would become a public header of internals. Read it in its order: helpers
// and the projection of a gap (top), the pair searches, walls and ends, cell exits, quiet times.
#include "turtlegas/sim/field_toi.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace turtlegas::sim {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

bool at_rest(const FieldFlight& f) { return f.w == 0.0 && f.a == Vec2{} && f.v == Vec2{}; }

// ---- The tan-half-angle quadratic -------------------------------------------------------------
// A constant plus a sinusoid of theta = w t, f = f0 + P sin(theta) + Q (1 - cos theta), times
// 1 + tau^2 (tau = tan(theta/2) > -inf) is f0 + 2 P tau + (f0 + 2 Q) tau^2: with T = 2 tau / w,
// a quadratic q(T) = c0 + 2 b T + c2 T^2 whose coefficients stay finite as w -> 0 (it tends to the
// straight-line or parabola quadratic in t, and T -> t). T runs over (-inf, inf) once per period:
// T >= 0 is the first half period (|w| t = 2 atan(|w| T / 2)), T = +-inf the middle, T < 0 the
// second half; sign(f) = sign(q) and T grows with t, so f's falls are q's falls.

// The phase |w| t in [0, 2 pi) of T = num / den (den == 0: T infinite, phase pi), for knots.
double phase_of(double num, double den, double aw) {
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
double time_of(double num, double den, double aw) {
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
double falling_time(double c0, double b, double c2, double disc, double aw) {
  if (!(disc > 0.0)) return -1.0;
  const double sq = std::sqrt(disc);
  if (b < 0.0) return time_of(c0, sq - b, aw);
  return time_of(-(b + sq), c2, aw);
}

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
int critical_phases(const Projection& p, double* out) {
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
int reach_windows(const Projection& p, double rho, const Gap1* gaps, int ngaps, double t_begin, double t_end,
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

// Segment-to-segment distance (0 when they cross).
double segment_distance(Vec2 a0, Vec2 a1, Vec2 b0, Vec2 b1) {
  auto point_seg = [](Vec2 q, Vec2 s0, Vec2 s1) {
    const Vec2 d = s1 - s0;
    const double l2 = norm2(d);
    const double t = l2 > 0.0 ? std::clamp(dot(q - s0, d) / l2, 0.0, 1.0) : 0.0;
    return norm(q - (s0 + t * d));
  };
  const Vec2 da = a1 - a0, db = b1 - b0;
  const double c1 = cross(da, b0 - a0), c2 = cross(da, b1 - a0), c3 = cross(db, a0 - b0), c4 = cross(db, a1 - b0);
  if (((c1 > 0.0 && c2 < 0.0) || (c1 < 0.0 && c2 > 0.0)) && ((c3 > 0.0 && c4 < 0.0) || (c3 < 0.0 && c4 > 0.0)))
    return 0.0;
  return std::min(std::min(point_seg(a0, b0, b1), point_seg(a1, b0, b1)),
                  std::min(point_seg(b0, a0, a1), point_seg(b1, a0, a1)));
}

// ---- The general pair: g(t) = |r(t)|^2 - sigma^2 ---------------------------------------------
struct PairSample {
  double g = 0.0, dg = 0.0;    // g(t), g'(t)
  double eg = 0.0, edg = 0.0;  // bounds on their evaluation errors
  double r = 0.0, v = 0.0;     // upper bounds on |r(t)|, |r'(t)|
};

class PairGap {
 public:
  PairGap(Vec2 r0, const FieldFlight& f1, const FieldFlight& f2, double sigma)
      : r0_(r0), f1_(f1), f2_(f2), sigma2_(sigma * sigma), nr0_(norm(r0)), nv1_(norm(f1.v)), nv2_(norm(f2.v)),
        na1_(norm(f1.a)), na2_(norm(f2.a)), acc1_(norm(field_acceleration(f1))), acc2_(norm(field_acceleration(f2))) {}

  // |r''(t)| <= |x1''| + |x2''|, each constant along its flight.
  double acc_bound() const { return acc1_ + acc2_; }

  // Both bodies have envelopes (flight_envelope): x_i(t) = gc_i(t) + P_i(t) with |P_i| = rho_i
  // exactly and gc_i moving straight, so with D(t) = gc_2(t) - gc_1(t)
  //   |r(t)| >= |D(t)| - rho_1 - rho_2   and   |r(t)| >= |rho_2 - rho_1| - |D(t)|
  // (outside the sum of the circles, or inside the difference: a body circling round a point that
  // its circle does not reach). Far better than the Taylor bounds for small fast circles, whose
  // |r''| is large but whose wiggle is tiny, and for large circles round a wall end.
  void set_envelopes(const Envelope& e1, const Envelope& e2, double sigma) {
    env_ = e1.bounded && e2.bounded;
    dc_ = e2.centre - e1.centre;
    du_ = e2.drift - e1.drift;
    const double margin = (e1.margin + e2.margin) * (1.0 + 1e-12) + 4.0 * kEps * (e1.radius + e2.radius);
    outer_ = (e1.rho + e2.rho + sigma) * (1.0 + 1e-12) + margin;
    inner_ = std::abs(e2.rho - e1.rho) * (1.0 - 1e-12) - sigma * (1.0 + 1e-12) - margin;
  }
  // The longest s >= 0 such that the envelopes prove g > 0 during [t - s, t + s].
  double envelope_step(double t) const {
    if (!env_) return 0.0;
    const double d = norm(dc_ + t * du_);
    const double clear = std::max(d - outer_, inner_ - d);
    if (!(clear > 0.0)) return 0.0;
    const double u = norm(du_);
    return u == 0.0 ? kNever : clear / u * (1.0 - 1e-12);
  }

  // {g(t), g'(t)}.
  GapD gap_d(double t) const {
    Vec2 d1, d2, v1, v2;
    double m = 0.0, mv = 0.0;
    body(f1_, nv1_, na1_, t, d1, v1, m, mv);
    body(f2_, nv2_, na2_, t, d2, v2, m, mv);
    const Vec2 r = r0_ + (d2 - d1);
    return {norm2(r) - sigma2_, 2.0 * dot(r, v2 - v1)};
  }

  // g''(0) = 2 |r'(0)|^2 + 2 r(0).r''(0).
  double curvature0() const {
    const Vec2 dv = f2_.v - f1_.v;
    return 2.0 * norm2(dv) + 2.0 * dot(r0_, field_acceleration(f2_) - field_acceleration(f1_));
  }

  PairSample sample(double t) const {
    Vec2 d1, d2, v1, v2;
    double m1 = 0.0, m2 = 0.0, mv1 = 0.0, mv2 = 0.0;
    body(f1_, nv1_, na1_, t, d1, v1, m1, mv1);
    body(f2_, nv2_, na2_, t, d2, v2, m2, mv2);
    const Vec2 r = r0_ + (d2 - d1);
    const Vec2 rv = v2 - v1;
    const double nr = norm(r), nrv = norm(rv);
    // Rounding of the sums (a few ulps of each term's magnitude) and the phase error of w t (half an
    // ulp of theta moves a body by |v| t eps), with a factor of 4 to spare.
    const double er = 16.0 * kEps * (nr0_ + m1 + m2) + 4.0 * kEps * t * (norm(v1) + norm(v2));
    const double ev = 16.0 * kEps * (mv1 + mv2) + 4.0 * kEps * t * (acc1_ + acc2_);
    PairSample s;
    s.g = norm2(r) - sigma2_;
    s.dg = 2.0 * dot(r, rv);
    s.eg = (2.0 * nr + er) * er + 4.0 * kEps * (nr * nr + sigma2_);
    s.edg = 2.0 * (nr * ev + nrv * er + er * ev) + 8.0 * kEps * nr * nrv;
    s.r = nr + er;
    s.v = nrv + ev;
    return s;
  }

 private:
  static void body(const FieldFlight& f, double nv, double na, double t, Vec2& d, Vec2& v, double& m, double& mv) {
    if (at_rest(f)) {
      d = {};
      v = {};
      return;
    }
    const FlightCoefficients k = flight_coefficients(f.w, t);
    const Vec2 jv = turn_cw(f.v), ja = turn_cw(f.a);
    d = k.s * f.v + k.c * jv + k.ca * f.a + k.da * ja;
    v = k.cos_theta * f.v + k.sin_theta * jv + k.s * f.a + k.c * ja;
    m = (std::abs(k.s) + std::abs(k.c)) * nv + (std::abs(k.ca) + std::abs(k.da)) * na;
    mv = (std::abs(k.cos_theta) + std::abs(k.sin_theta)) * nv + (std::abs(k.s) + std::abs(k.c)) * na;
  }

  Vec2 r0_;
  FieldFlight f1_, f2_;
  double sigma2_, nr0_, nv1_, nv2_, na1_, na2_, acc1_, acc2_;
  bool env_ = false;
  Vec2 dc_, du_;
  double outer_ = 0.0, inner_ = 0.0;
};

// The largest s such that lo + G s' - M s'^2 / 2 > 0 for all s' in [0, s), lo > 0: the positive
// root, in the form that adds quantities of the same sign.
double safe_step(double lo, double G, double M) {
  if (!(lo > 0.0)) return 0.0;
  const double sq = std::sqrt(G * G + 2.0 * M * lo);
  if (G < 0.0) return 2.0 * lo / (sq - G);
  return M > 0.0 ? (G + sq) / M : kNever;
}

struct Node {
  double a, b;
  PairSample sa, sb;
};

// The search of toi_field_disc_disc_bracketed on [t_begin, t_end], s_begin the sample at t_begin.
//
// On a node [a, b] (h = b - a) the bounds A >= |r''|, |r'| <= V = |r'(a)| + A h and |r| <= R =
// |r(a)| + |r'(a)| h + A h^2/2 (or the same from b, whichever is smaller) give
//   -M_lo <= g'' <= M_hi,  M_lo = 2 R A,  M_hi = 2 V^2 + 2 R A,
// so from either end g lies between two parabolas. With the evaluation errors subtracted:
//   * g > 0 on the node if the lower parabolas from a and from b, positive at their ends, stay
//     positive over lengths that together cover h (safe_step; the envelopes' bound, when both
//     bodies have one, may lengthen them: PairGap::envelope_step); g < 0 likewise with the upper
//     parabolas;
//   * g is monotone if g'(a) + M_hi h < 0 or g'(b) + M_lo h < 0 (falling), or the mirror (rising).
// A node whose computed ends fall (g(a) >= 0 > g(b)) and is monotone is refined; a node proven
// positive, negative or monotone without such a fall holds no fall (of the exact g, deeper than the
// evaluation error) and is dropped; every other node is split, leftmost first, so the first fall is
// found first. Nodes narrower than 4 eps t_end are decided by their end points' signs alone: a dip
// missed there is shallower than M_hi (4 eps t_end)^2 / 2.
//
// A call stops after kMaxSplits splits, but never by deciding a node on its ends: the nodes are
// taken leftmost first, so when it stops at node [a, b] every node left of a has been dropped (proven
// free of a fall) and [t_begin, a] holds none. It returns {kNever, a}: "nothing up to a", and the
// caller continues from there (toi_field_disc_disc_bracketed re-centres the flights at a; the engine
// could re-predict there instead). It stops only when a > t_begin, so each call makes progress
// (a node whose left end is still t_begin can be split only by halving, at most ~50 times down to
// 4 eps t_end, or trimmed from the right, by a quarter each time: a bounded number of splits).
// The stack cannot overflow: it holds one right sibling per halving on the path to the current
// node (a trim replaces a node by one), and a path has at most log2(1 / (4 eps)) = 50 halvings
// before its nodes are below 4 eps t_end; 160 entries leave room to spare (if it ever were full the
// call would stop at the node, as above, rather than decide it on its ends).
constexpr int kMaxSplits = 4000;

PartialToi bracketed_search(const PairGap& pg, double t_begin, const PairSample& s_begin, double t_end) {
  const double A = pg.acc_bound();
  const double h_min = 4.0 * kEps * t_end;
  Node stack[160];
  int top = 0;
  stack[top++] = {t_begin, t_end, s_begin, pg.sample(t_end)};
  int splits = 0;
  constexpr double kInflate = 1.0 + 1e-12;  // the bounds' own rounding
  while (top > 0) {
    const Node nd = stack[--top];
    if ((splits >= kMaxSplits || top + 2 > 160) && nd.a > t_begin) return {kNever, nd.a};
    const double h = nd.b - nd.a;
    const PairSample& sa = nd.sa;
    const PairSample& sb = nd.sb;
    const double V = std::min(sa.v, sb.v) + A * h;
    const double R = std::min(sa.r + sa.v * h, sb.r + sb.v * h) + 0.5 * A * h * h;
    const double m_lo = kInflate * 2.0 * R * A;
    const double m_hi = kInflate * (2.0 * V * V + 2.0 * R * A);
    const bool falling = sa.dg + sa.edg + m_hi * h < 0.0 || sb.dg + sb.edg + m_lo * h < 0.0;
    const bool rising = sa.dg - sa.edg - m_lo * h > 0.0 || sb.dg - sb.edg - m_hi * h > 0.0;
    const bool can_split = h > h_min && top + 2 <= 160;
    const bool fall_between = sa.g >= 0.0 && sb.g < 0.0;
    auto refine = [&] {
      return PartialToi{
          refine_fall_newton([&](double t) { return pg.gap_d(t); }, nd.a, GapD{sa.g, sa.dg}, nd.b, GapD{sb.g, sb.dg}),
          t_end};
    };
    if (fall_between && (falling || !can_split)) return refine();
    if (!fall_between && (falling || rising || !can_split)) continue;
    // The parts next to each end on which g keeps that end's sign, proven by the parabolas.
    // A positive end also gets the envelopes' step.
    const double step_a = sa.g >= 0.0 ? std::max(safe_step(sa.g - sa.eg, sa.dg - sa.edg, m_lo), pg.envelope_step(nd.a))
                                       : safe_step(-(sa.g + sa.eg), -(sa.dg + sa.edg), m_hi);
    const double step_b = sb.g >= 0.0
                              ? std::max(safe_step(sb.g - sb.eg, -(sb.dg + sb.edg), m_lo), pg.envelope_step(nd.b))
                              : safe_step(-(sb.g + sb.eg), sb.dg - sb.edg, m_hi);
    if (step_a + step_b >= h) {
      if (fall_between) return refine();  // only by rounding: the fall is at the seam
      continue;
    }
    ++splits;
    // Drop the proven parts when they are a good share of the node (near a root this steps
    // towards it like conservative advancement); otherwise halve.
    if (step_a >= 0.25 * h || step_b >= 0.25 * h) {
      const double a = step_a >= 0.25 * h ? nd.a + step_a : nd.a;
      const double b = step_b >= 0.25 * h ? nd.b - step_b : nd.b;
      stack[top++] = {a, b, a == nd.a ? sa : pg.sample(a), b == nd.b ? sb : pg.sample(b)};
      continue;
    }
    const double m = nd.a + 0.5 * h;
    const PairSample sm = pg.sample(m);
    stack[top++] = {m, nd.b, sm, sb};
    stack[top++] = {nd.a, m, sa, sm};
  }
  return {kNever, t_end};
}

// The time after which two envelopes are apart for good (the larger root of |dc + du t| = reach,
// reach inflated by 1e-9 so that the root's own rounding cannot cut a contact off), kNever when
// they never part (or the numbers say nothing), -1 when they never meet at all.
double envelopes_part(const Envelope& e1, const Envelope& e2) {
  const Vec2 dc = e2.centre - e1.centre, du = e2.drift - e1.drift;
  const double reach = (e1.radius + e2.radius + e1.margin + e2.margin) * (1.0 + 1e-9);
  const double u2 = norm2(du);
  if (!std::isfinite(reach) || !std::isfinite(u2) || !is_finite(dc)) return kNever;
  if (u2 == 0.0) return norm(dc) > reach ? -1.0 : kNever;
  const double b = dot(dc, du);
  const double cr = cross(dc, du);
  const double disc = reach * reach * u2 - cr * cr;  // the memo's radicand: b^2 - u2 (|dc|^2 - reach^2)
  if (!std::isfinite(disc)) return kNever;
  if (!(disc > 0.0)) return -1.0;
  const double sq = std::sqrt(disc);
  // Of the roots (-b +- sq) / u2, the larger, in the form that adds like signs.
  if (b < 0.0) return (sq - b) / u2;
  return (reach - norm(dc)) * (reach + norm(dc)) / (b + sq);
}

}  // namespace

// ---- Two discs, relative rotation --------------------------------------------------------------
double toi_field_disc_disc_rotating(Vec2 r, Vec2 dv, double w, double sigma, double horizon) {
  if (w == 0.0) {
    const double t = toi_disc_disc(r, dv, sigma);
    return t <= horizon ? t : kNever;
  }
  // r(t) = r + s dv + c J(dv), so g = |r(t)|^2 - sigma^2 = g0 + (2 b / w) sin(theta) + (1 - cos theta)
  // (2 k / w + 2 |dv|^2 / w^2) with b = r.dv, k = cross(r, dv): of the form above, with
  //   c2 = |dv|^2 + w k + g0 w^2 / 4 = |m|^2 - (w sigma / 2)^2,  m = dv + (w/2) perp(r),
  // (w^2/4 times the gap half a period on), and, as r.m = b,
  //   b^2 - g0 c2 = sigma^2 (|m|^2 + (w/2)^2 g0) - cross(r, m)^2,
  // the memo's radicand sigma^2 v^2 - (r x v)^2 with v -> m, free of the cancellation of b^2 against
  // |m|^2 |r|^2 for discs far apart.
  const double b = dot(r, dv);
  const double g0 = norm2(r) - sigma * sigma;
  const double e2 = norm2(dv) + w * cross(r, dv);  // g''(0) / 2
  if (g0 <= 0.0 && (b < 0.0 || (b == 0.0 && e2 < 0.0))) return 0.0;
  const double hw = 0.5 * w;
  const Vec2 m = dv + hw * perp(r);
  const double ws = hw * sigma;
  const double m2 = norm2(m);
  const double c2 = m2 - ws * ws;
  const double cm = cross(r, m);
  const double disc = sigma * sigma * (m2 + hw * hw * g0) - cm * cm;
  const double t = falling_time(g0, b, c2, disc, std::abs(w));
  if (t < 0.0) return kNever;
  return t <= horizon ? t : kNever;
}

// ---- Two discs, any flights --------------------------------------------------------------------
PartialToi toi_field_disc_disc_partial(Vec2 r, const FieldFlight& f1, const FieldFlight& f2, double sigma,
                                       double horizon) {
  if (!(horizon >= 0.0)) return {kNever, horizon};
  {
    const PairGap pg0(r, f1, f2, sigma);
    const PairSample s0 = pg0.sample(0.0);
    if (s0.g <= 0.0 && (s0.dg < 0.0 || (s0.dg == 0.0 && pg0.curvature0() < 0.0))) return {0.0, 0.0};
  }
  // Where both bodies have envelopes, nothing can happen before they can touch nor after they have
  // parted for good: search only in between.
  double t_begin = 0.0, t_end = horizon;
  const Envelope e1 = flight_envelope({}, f1, 0.0), e2 = flight_envelope(r, f2, sigma);
  PairGap pg(r, f1, f2, sigma);
  pg.set_envelopes(e1, e2, sigma);
  if (e1.bounded && e2.bounded) {
    const double part = envelopes_part(e1, e2);
    if (part < 0.0) return {kNever, horizon};
    t_end = std::min(t_end, part);
    t_begin = quiet_time_pair(e1, e2);
  }
  if (!std::isfinite(t_end) || !(t_begin < t_end)) return {kNever, horizon};
  PartialToi res = bracketed_search(pg, t_begin, pg.sample(t_begin), t_end);
  if (res.t == kNever && res.reached >= t_end) res.reached = horizon;  // complete: nothing up to the horizon
  return res;
}

double toi_field_disc_disc_bracketed(Vec2 r, const FieldFlight& f1, const FieldFlight& f2, double sigma,
                                     double horizon) {
  // One search at a time, each proving [0, reached] free of a contact; a search that stops short
  // is continued from where it stopped, with both flights re-centred there (positions relative to
  // each other, so nothing large is added to anything small).
  // At most kMaxContinuations searches (some 2.6e5 splits): a horizon of very many periods of a
  // circle that keeps coming near without touching would otherwise cost without bound. Past that
  // it answers kNever, as it does when the time can no longer advance in double.
  constexpr int kMaxContinuations = 64;
  double t0 = 0.0;
  FieldFlight g1 = f1, g2 = f2;
  for (int k = 0; k < kMaxContinuations; ++k) {
    const PartialToi p = toi_field_disc_disc_partial(r, g1, g2, sigma, horizon - t0);
    if (p.t != kNever) return t0 + p.t;
    if (!(p.reached < horizon - t0) || !(p.reached > 0.0) || !(t0 + p.reached > t0)) return kNever;
    r += field_displacement(g2, p.reached) - field_displacement(g1, p.reached);
    g1.v = field_velocity(g1, p.reached);
    g2.v = field_velocity(g2, p.reached);
    t0 += p.reached;
  }
  return kNever;
}

double toi_field_disc_disc(Vec2 r, const FieldFlight& f1, const FieldFlight& f2, double sigma, double horizon) {
  if (f1.w == f2.w && f1.a == f2.a) return toi_field_disc_disc_rotating(r, f2.v - f1.v, f1.w, sigma, horizon);
  if (f1.w == 0.0 && f2.w == 0.0) return toi_disc_point_accel(r, f2.v - f1.v, f2.a - f1.a, sigma, horizon);
  if (at_rest(f1) && f2.a == Vec2{}) return toi_field_disc_disc_rotating(r, f2.v, f2.w, sigma, horizon);
  if (at_rest(f2) && f1.a == Vec2{}) return toi_field_disc_disc_rotating(-r, f1.v, f1.w, sigma, horizon);
  return toi_field_disc_disc_bracketed(r, f1, f2, sigma, horizon);
}

// ---- A disc and a wall face ----------------------------------------------------------------------
double toi_field_disc_segment(Vec2 rel, const FieldFlight& f, const Segment& s, double radius, double horizon) {
  if (f.w == 0.0) {
    const double t = toi_disc_segment(rel, f.v, f.a, s, radius);
    return t <= horizon ? t : kNever;
  }
  const Projection p(f, s.n);
  const double d0 = dot(rel, s.n);
  const double side = d0 >= 0.0 ? 1.0 : -1.0;
  auto foot_at = [&](double t) { return dot(rel + field_displacement(f, t), s.u); };
  auto foot_on = [&](double t) {
    const double foot = foot_at(t);
    return foot >= 0.0 && foot <= s.len;
  };
  // Touching and approaching the near face with the foot on the segment collides now.
  if (side * d0 - radius <= 0.0 && (side * p.A < 0.0 || (side * p.A == 0.0 && side * p.acc_n < 0.0)) && foot_on(0.0))
    return 0.0;
  // Both faces: the far one's gap starts negative and can rise and fall again (the disc passes the
  // line beside the segment and comes back onto the other face).
  const Gap1 gaps[2] = {{side * d0 - radius, side}, {-side * d0 - radius, -side}};
  const double aw = std::abs(f.w);
  if (p.D == 0.0) {
    // No drift across the wall: each face's gap is a constant plus a sinusoid (the tan-half-angle
    // quadratic with c0 = gap(0), b = sign (n.v)/2, c2 = c0 w^2/4 + sign (n.x''(0))/2), falling once
    // per period at phase_k = phase_0 + 2 pi k. The motion repeats every period up to the drift
    // u_d P along the wall, so the foot at the k-th fall is foot_0 + k (u.u_d) P: the first k that
    // puts it on the segment is found in closed form and confirmed by evaluating the foot there.
    const double period = kTwoPi / aw;
    const double foot_step = f.a == Vec2{} ? 0.0 : cross(s.u, f.a) / f.w * period;
    double best = kNever;
    for (const Gap1& g : gaps) {
      const double b = 0.5 * g.sign * p.A;
      const double c2 = g.g0 * (0.25 * f.w * f.w) + 0.5 * g.sign * p.acc_n;
      const double t0 = falling_time(g.g0, b, c2, b * b - g.g0 * c2, aw);
      if (t0 < 0.0) continue;
      auto time_k = [&](double k) { return t0 + k * period; };
      if (t0 >= best || t0 > horizon) continue;
      const double foot0 = foot_at(t0);
      if (foot0 >= 0.0 && foot0 <= s.len) {
        best = t0;
        continue;
      }
      if (foot_step == 0.0) continue;  // the same foot every period
      double k = -1.0;
      if (foot0 < 0.0 && foot_step > 0.0) k = std::ceil(-foot0 / foot_step);
      if (foot0 > s.len && foot_step < 0.0) k = std::ceil((foot0 - s.len) / -foot_step);
      if (k < 1.0 || !(k + 1.0 > k)) continue;  // (a k beyond 2^53 periods is no time a double can tell)
      // Rounding of foot_0 + k step against the evaluated foot: look at k - 1, k, k + 1.
      for (double kk = std::max(1.0, k - 1.0); kk <= k + 1.0; kk += 1.0) {
        const double tk = time_k(kk);
        if (tk >= best || tk > horizon) break;
        if (foot_on(tk)) {
          best = tk;
          break;
        }
      }
    }
    return best <= horizon ? best : kNever;
  }
  // Drift across the wall: monotone pieces between the closed-form critical points, inside the
  // window where the circle can reach either face.
  // x(t) = gc(t) + P(t) with |P(t)| = rho exactly and gc moving straight at u_d, so a contact at t
  // puts a point of a face's contact segment (the segment moved by radius along +-n) on the circle
  // of radius rho about gc(t): over [ta, tb] the guiding centre's path G must come within rho of
  // that segment and some end of G must be at least rho from some end of it. A circle passing
  // beside the segment, or around it, for many periods is ruled out a stretch at a time.
  const double rho = gyration_radius(f);
  const Vec2 gc0 = rel - (f.w * perp(f.v) - f.a) / (f.w * f.w), ud = drift_velocity(f);
  const double fixed_margin = 64.0 * kEps * (norm(rel) + 2.0 * rho + radius + s.len);
  auto relevant = [&](double ta, double tb) {
    const Vec2 g0 = gc0 + ta * ud, g1 = gc0 + tb * ud;
    const double margin = fixed_margin + 64.0 * kEps * norm(ud) * tb;
    for (double face : {1.0, -1.0}) {
      const Vec2 s0 = (face * radius) * s.n, s1 = s0 + s.len * s.u;
      if (segment_distance(g0, g1, s0, s1) > rho + margin) continue;
      const double far = std::max(std::max(norm(g0 - s0), norm(g0 - s1)), std::max(norm(g1 - s0), norm(g1 - s1)));
      if (far >= rho - margin) return true;
    }
    return false;
  };
  int which = 0;
  const double t = first_fall_windows(p, rho, gaps, 2, horizon, foot_on, relevant, &which);
  return t <= horizon ? t : kNever;
}

// ---- A disc and a point ----------------------------------------------------------------------
double toi_field_disc_point(Vec2 rel, const FieldFlight& f, double radius, double horizon) {
  if (f.w == 0.0) return toi_disc_point_accel(rel, f.v, f.a, radius, horizon);
  if (f.a == Vec2{}) return toi_field_disc_disc_rotating(rel, f.v, f.w, radius, horizon);
  return toi_field_disc_disc_bracketed(rel, FieldFlight{}, f, radius, horizon);
}

// ---- Cell exits ------------------------------------------------------------------------------
// ---- A drift-free circle's exit from a box -----------------------------------------------------
// field_axis_exit's closed form for both axes at once, with one arctangent instead of four: the four
// sides' falling roots T = num/den are ordered without it (the phase grows with T within each half
// period, the first half before the second), and only the earliest is turned into a time. Sides
// whose T lie within a relative 1e-6 of the earliest's are timed too and the tie rules kept (the
// first in the order x upper, x lower, y upper, y lower wins equal times, as field_axis_exit and
// earlier_exit decide), so the answer is field_axis_exit's to the bit but for roots closer to
// half a period than ~1e-10 of it, where simultaneous exits through a corner may come out in the
// other order (either is a correct crossing).
BoxExit field_box_exit_drift_free(Vec2 x, const FieldFlight& f, Vec2 lo, Vec2 hi) {
  const double aw = std::abs(f.w);
  struct Candidate {
    double num = 0.0, den = 1.0, q = 0.0;
    int half = 3;  // -1: now; 0: first half period; 1: at half a period; 2: second half; 3: none
  };
  Candidate c[4];
  for (int axis = 0; axis < 2; ++axis) {
    const Vec2 n = axis == 0 ? Vec2{1.0, 0.0} : Vec2{0.0, 1.0};
    const Projection p(f, n);
    const double xv = axis == 0 ? x.x : x.y, l = axis == 0 ? lo.x : lo.y, h = axis == 0 ? hi.x : hi.y;
    const Gap1 gaps[2] = {{h - xv, -1.0}, {xv - l, 1.0}};
    for (int g = 0; g < 2; ++g) {
      Candidate& k = c[2 * axis + g];
      const double c0 = gaps[g].g0, b = 0.5 * gaps[g].sign * p.A, e2 = 0.5 * gaps[g].sign * p.acc_n;
      if (c0 <= 0.0 && (b < 0.0 || (b == 0.0 && e2 < 0.0))) {
        k.half = -1;
        continue;
      }
      const double c2 = c0 * (0.25 * f.w * f.w) + e2;
      const double disc = b * b - c0 * c2;
      if (!(disc > 0.0)) continue;  // falling_time's miss
      const double sq = std::sqrt(disc);
      double num = b < 0.0 ? c0 : -(b + sq), den = b < 0.0 ? sq - b : c2;
      if (den < 0.0) num = -num, den = -den;  // (time_of's normalisation)
      k.num = num;
      k.den = den;
      if (num >= 0.0 && den > 0.0) k.half = 0, k.q = num / den;
      else if (den == 0.0) k.half = 1;
      else k.half = 2, k.q = num / den;
    }
  }
  int w = -1;
  for (int k = 0; k < 4; ++k)
    if (c[k].half != 3 && (w < 0 || c[k].half < c[w].half || (c[k].half == c[w].half && c[k].q < c[w].q))) w = k;
  BoxExit e;
  if (w < 0) return e;
  auto time = [&](int k) { return c[k].half == -1 ? 0.0 : time_of(c[k].num, c[k].den, aw); };
  e = {time(w), w / 2, w % 2 == 0};
  for (int k = 0; k < 4; ++k) {
    if (k == w || c[k].half != c[w].half) continue;
    if (!(std::abs(c[k].q - c[w].q) <= 1e-6 * std::max(std::abs(c[k].q), std::abs(c[w].q)))) continue;
    const double t = time(k);
    if (t < e.t || (t == e.t && k < 2 * e.axis + (e.upper ? 0 : 1))) e = {t, k / 2, k % 2 == 0};
  }
  return e;
}

AxisExit field_axis_exit(double x, const FieldFlight& f, int axis, double lo, double hi, double horizon) {
  const Vec2 n = axis == 0 ? Vec2{1.0, 0.0} : Vec2{0.0, 1.0};
  if (f.w == 0.0) {
    const AxisExit e = axis_exit(x, dot(n, f.v), dot(n, f.a), lo, hi);
    return e.t <= horizon ? e : AxisExit{};
  }
  const Projection p(f, n);
  // The gaps hi - x(t) (sign -1) and x(t) - lo (sign +1).
  const Gap1 gaps[2] = {{hi - x, -1.0}, {x - lo, 1.0}};
  const double aw = std::abs(f.w);
  AxisExit best;
  if (p.D == 0.0) {
    // No drift along the axis: per side the tan-half-angle quadratic; the coordinate repeats every
    // period, so an exit that does not happen in the first one never does.
    for (int g = 0; g < 2; ++g) {
      const double c0 = gaps[g].g0, b = 0.5 * gaps[g].sign * p.A, e2 = 0.5 * gaps[g].sign * p.acc_n;
      double t;
      if (c0 <= 0.0 && (b < 0.0 || (b == 0.0 && e2 < 0.0))) {
        t = 0.0;
      } else {
        const double c2 = c0 * (0.25 * f.w * f.w) + e2;
        t = falling_time(c0, b, c2, b * b - c0 * c2, aw);
        if (t < 0.0) continue;
      }
      if (t < best.t) best = {t, g == 0};
    }
    return best.t <= horizon ? best : AxisExit{};
  }
  for (int g = 0; g < 2; ++g) {
    const double c0 = gaps[g].g0, c1 = gaps[g].sign * p.A, e2 = gaps[g].sign * p.acc_n;
    if (c0 <= 0.0 && (c1 < 0.0 || (c1 == 0.0 && e2 < 0.0))) return {0.0, g == 0};
  }
  int which = 0;
  const double t = first_fall_windows(p, gyration_radius(f), gaps, 2, horizon, [](double) { return true; },
                                      [](double, double) { return true; }, &which);
  if (!(t <= horizon)) return {};
  return {t, which == 0};
}

// ---- Envelopes and quiet times -------------------------------------------------------------
Envelope flight_envelope(Vec2 x, const FieldFlight& f, double radius) {
  if (f.w == 0.0) {
    if (at_rest(f)) return {x, {}, radius, 0.0, radius, 4.0 * kEps * (norm(x) + radius), true};
    return {};
  }
  const double rho = gyration_radius(f);
  const Vec2 centre = guiding_centre(x, f), drift = drift_velocity(f);
  // A w so small that w^2 underflows, or a circle beyond 1e150: nothing useful to bound with.
  if (!(rho <= 1e150) || !is_finite(centre) || !is_finite(drift)) return {};
  // Centre and radius carry a few ulps of |x| + rho; the engine's own positions, from
  // field_displacement, a few ulps of the displacement's terms: 64 eps covers both generously.
  return {centre, drift, radius + rho, rho, radius, 64.0 * kEps * (norm(x) + 2.0 * rho + radius), true};
}

namespace {

// (clearance - reach) / speed, shrunk by a relative 1e-12 so that it is a lower bound.
double quiet_time(double clearance, double speed) {
  if (!(clearance > 0.0)) return 0.0;
  if (speed == 0.0) return kNever;
  return clearance / speed * (1.0 - 1e-12);
}

}  // namespace

double quiet_time_box(const Envelope& e, Vec2 lo, Vec2 hi) {
  if (!e.bounded) return 0.0;
  const double reach = e.radius + e.margin + 4.0 * kEps * (norm(lo) + norm(hi));
  double t = kNever;
  const double c[2] = {e.centre.x, e.centre.y}, u[2] = {e.drift.x, e.drift.y};
  const double l[2] = {lo.x, lo.y}, h[2] = {hi.x, hi.y};
  for (int k = 0; k < 2; ++k) {
    const double below = c[k] - reach - l[k], above = h[k] - (c[k] + reach);
    if (!(below > 0.0 && above > 0.0)) return 0.0;
    if (u[k] > 0.0) t = std::min(t, quiet_time(above, u[k]));
    if (u[k] < 0.0) t = std::min(t, quiet_time(below, -u[k]));
  }
  return t;
}

double quiet_time_segment(const Envelope& e, const Segment& s) {
  if (!e.bounded) return 0.0;
  const Vec2 rel = e.centre - s.p1;
  const double foot = std::clamp(dot(rel, s.u), 0.0, s.len);
  const double dist = norm(rel - foot * s.u);
  const double reach = e.radius + e.margin + 8.0 * kEps * (norm(e.centre) + norm(s.p1) + s.len);
  return quiet_time(dist - reach, norm(e.drift));
}

double quiet_time_point(const Envelope& e, Vec2 p) {
  if (!e.bounded) return 0.0;
  const double reach = e.radius + e.margin + 8.0 * kEps * (norm(e.centre) + norm(p));
  return quiet_time(norm(e.centre - p) - reach, norm(e.drift));
}

double quiet_time_pair(const Envelope& e1, const Envelope& e2) {
  if (!e1.bounded || !e2.bounded) return 0.0;
  const double reach = e1.radius + e2.radius + e1.margin + e2.margin;
  return quiet_time(norm(e2.centre - e1.centre) - reach, norm(e2.drift - e1.drift));
}

}  // namespace turtlegas::sim
