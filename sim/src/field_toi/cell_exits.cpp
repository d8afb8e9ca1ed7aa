// SPDX-License-Identifier: MIT
// A disc on a field flight leaving a cell: a drift-free circle's exit from a box in closed form,
// one axis's exit with any flight.
#include <algorithm>
#include <cmath>

#include "detail.hpp"
#include "turtlegas/sim/field_toi.hpp"

namespace turtlegas::sim {
using namespace field_toi_detail;

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

}  // namespace turtlegas::sim
