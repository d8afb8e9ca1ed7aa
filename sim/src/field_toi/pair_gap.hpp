// SPDX-License-Identifier: MIT
// Private to sim/src/field_toi/: the general pair's gap g(t) = |r(t)|^2 - sigma^2 of two discs on
// any field flights, sampled with bounds on its evaluation errors, and the bracketed search of its
// first fall (toi_field_disc_disc_bracketed's engine).
#pragma once

#include "detail.hpp"

namespace turtlegas::sim::field_toi_detail {

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

/// The search of toi_field_disc_disc_bracketed on [t_begin, t_end], s_begin the sample at t_begin:
/// the first fall, or {kNever, a} when it stopped after its splits with [t_begin, a] proven free
/// of one (pair_gap.cpp says how).
PartialToi bracketed_search(const PairGap& pg, double t_begin, const PairSample& s_begin, double t_end);

}  // namespace turtlegas::sim::field_toi_detail
