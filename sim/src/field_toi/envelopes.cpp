// SPDX-License-Identifier: MIT
// Envelopes of field flights (a circle of radius rho about a guiding centre that drifts
// straight) and the quiet times they prove: how long a body cannot reach a cell's sides, a
// wall, a point or another body.
#include <algorithm>
#include <cmath>

#include "detail.hpp"
#include "turtlegas/sim/field_toi.hpp"

namespace turtlegas::sim {
using namespace field_toi_detail;

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
