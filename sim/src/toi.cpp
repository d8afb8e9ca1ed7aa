// SPDX-License-Identifier: MIT
#include "turtlegas/sim/toi.hpp"

#include <algorithm>
#include <cmath>

namespace turtlegas::sim {

Segment make_segment(Vec2 from, Vec2 to) {
  const Vec2 d = to - from;
  const double len = norm(d);
  const Vec2 u = d / len;
  return {from, u, perp(u), len};
}

double toi_disc_segment(Vec2 rel, Vec2 v, Vec2 a, const Segment& s, double radius) {
  const double d0 = dot(rel, s.n);
  const double vn = dot(v, s.n), an = dot(a, s.n);
  auto on_segment = [&](double t) {
    const double foot = dot(rel + t * v + (0.5 * t * t) * a, s.u);
    return foot >= 0.0 && foot <= s.len;
  };
  // Walls are two-sided: measure the separation on the side the centre is on. Its gap is a
  // quadratic, so it falls at most once.
  const double side = d0 >= 0.0 ? 1.0 : -1.0;
  double best = kNever;
  const double t = first_approach_quadratic(side * d0 - radius, side * vn, 0.5 * side * an);
  if (t != kNever && on_segment(t)) best = t;
  // A field pulling the disc back towards its own side can carry it across the wall's line beyond
  // an end and bring it down onto the other face (a ball thrown up past the end of a shelf lands on
  // it). The other side's gap -side d - r starts negative, so it has to rise before it falls: its
  // fall is the larger root, where it opens downwards and both roots are positive (c1 > 0).
  if (side * an > 0.0) {
    const double c0 = -side * d0 - radius, c1 = -side * vn, c2 = -0.5 * side * an;
    const double disc = c1 * c1 - 4.0 * c2 * c0;
    if (c1 > 0.0 && disc > 0.0) {
      const double q = -0.5 * (c1 + std::sqrt(disc));  // both roots: q / c2 (the larger) and c0 / q
      const double t_far = q / c2;
      if (t_far < best && on_segment(t_far)) best = t_far;
    }
  }
  return best;
}

double toi_disc_point_accel(Vec2 rel, Vec2 v, Vec2 a, double radius, double t_max) {
  if (a.x == 0.0 && a.y == 0.0) {
    const double t = toi_disc_point(rel, v, radius);
    return t <= t_max ? t : kNever;
  }
  // |rel + v t + a t^2/2|^2 - radius^2, expanded in t.
  const double c[5] = {
      norm2(rel) - radius * radius,
      2.0 * dot(rel, v),
      norm2(v) + dot(rel, a),
      dot(v, a),
      0.25 * norm2(a),
  };
  return first_approach_poly(c, 4, t_max);
}

AxisExit axis_exit(double x, double v, double a, double lo, double hi) {
  const double t_hi = first_approach_quadratic(hi - x, -v, -0.5 * a);
  const double t_lo = first_approach_quadratic(x - lo, v, 0.5 * a);
  return t_hi <= t_lo ? AxisExit{t_hi, true} : AxisExit{t_lo, false};
}

void respond_disc_disc(Vec2& v1, Vec2& v2, double m1, double m2, Vec2 F, double e) {
  // Memo: v' = v - 2 (m2/M) ((v1 - v2).F / |F|^2) F, with 2 -> 1 + e.
  const double k = (1.0 + e) * dot(v2 - v1, F) / (norm2(F) * (m1 + m2));
  v1 += (k * m2) * F;
  v2 -= (k * m1) * F;
}

Vec2 respond_wall(Vec2 v, Vec2 n, double e) { return v - ((1.0 + e) * dot(v, n)) * n; }

Vec2 respond_point(Vec2 v, Vec2 F, double e) {
  return v - ((1.0 + e) * dot(v, F) / norm2(F)) * F;
}

}  // namespace turtlegas::sim
