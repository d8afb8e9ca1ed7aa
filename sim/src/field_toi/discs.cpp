// SPDX-License-Identifier: MIT
// Two discs on field flights: turning about each other in closed form, any flights by the
// bracketed search of their gap (pair_gap.hpp), and the dispatch between them.
#include <algorithm>
#include <cmath>

#include "pair_gap.hpp"
#include "turtlegas/sim/field_toi.hpp"

namespace turtlegas::sim {
using namespace field_toi_detail;
namespace {

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

}  // namespace turtlegas::sim
