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

namespace {

// The deforming segment of toi_disc_deforming_segment at time t, seen from the disc.
struct DeformingContact {
  Vec2 rel, v, a, d0, w;
  double radius;

  Vec2 d_at(double t) const { return d0 + t * w; }
  Vec2 y_at(double t) const { return rel + t * v + (0.5 * t * t) * a; }
  // Signed distance from the centre to the segment's line.
  double distance(double t) const {
    const Vec2 d = d_at(t);
    return cross(d, y_at(t)) / norm(d);
  }
  bool foot_on_segment(double t) const {
    const Vec2 d = d_at(t);
    const double s = dot(y_at(t), d);
    return s >= 0.0 && s <= norm2(d);
  }
  // d(distance)/dt at t = 0.
  double distance_rate0() const {
    const double l2 = norm2(d0);
    const double f0 = cross(d0, rel);
    const double f1 = cross(d0, v) + cross(w, rel);
    return (f1 - f0 * dot(d0, w) / l2) / std::sqrt(l2);
  }
  // Whether the disc overlaps the segment on `side` at t: inside the line's strip, foot on it.
  bool overlaps(double t, double side) const { return side * distance(t) - radius < 0.0 && foot_on_segment(t); }
};

}  // namespace

double deforming_line_accel(Vec2 rel, Vec2 v, Vec2 a, Vec2 d0, Vec2 w) {
  // sigma = f / L with f = cross(D, Y) = f0 + f1 t + f2 t^2 + ... and L = |D| = sqrt(Q),
  // Q = l0 + l1 t + l2 t^2: sigma'' = f''/L - 2 f' L'/L^2 - f L''/L^2 + 2 f L'^2/L^3 at t = 0,
  // with L' = Q'/(2L) and L'' = Q''/(2L) - Q'^2/(4 L^3).
  const double l0 = norm2(d0), l1 = 2.0 * dot(d0, w), l2 = norm2(w);
  const double f0 = cross(d0, rel), f1 = cross(d0, v) + cross(w, rel), f2 = 0.5 * cross(d0, a) + cross(w, v);
  const double L = std::sqrt(l0);
  const double Lp = l1 / (2.0 * L);
  const double Lpp = l2 / L - l1 * l1 / (4.0 * l0 * L);
  return (2.0 * f2 - 2.0 * f1 * Lp / L - f0 * Lpp / L + 2.0 * f0 * Lp * Lp / l0) / L;
}

double toi_disc_deforming_segment(Vec2 rel, Vec2 v, Vec2 a, Vec2 d0, Vec2 w, double radius, double t_max) {
  const double f0 = cross(d0, rel);
  if (f0 == 0.0 || !(t_max >= 0.0)) return kNever;  // on the line: overlapping, or beyond an end
  const DeformingContact c{rel, v, a, d0, w, radius};
  // Touching and approaching collides now; touching and receding looks for the next contact.
  // Touching at rate 0 with the line closing at second order (a disc touching the pivot of a
  // turning arm, whose point there does not move) collides now too, as a disc at rest on a fixed
  // wall under gravity does (first_approach_quadratic); the bounce then leaves it at the rest
  // threshold's speed (Restitution::bounce, with the press of the turning line).
  const double side0 = f0 > 0.0 ? 1.0 : -1.0;
  if (side0 * c.distance(0.0) - radius <= 0.0 && c.foot_on_segment(0.0)) {
    const double rate = side0 * c.distance_rate0();
    if (rate < 0.0 || (rate == 0.0 && side0 * deforming_line_accel(rel, v, a, d0, w) < 0.0)) return 0.0;
  }
  // f(t) = cross(D, Y) = f0 + f1 t + f2 t^2 + f3 t^3 and |D|^2 = l0 + l1 t + l2 t^2; the distance is
  // +-radius only where h = f^2 - radius^2 |D|^2 is zero.
  const Vec2 ah = 0.5 * a;
  const double f[4] = {f0, cross(d0, v) + cross(w, rel), cross(d0, ah) + cross(w, v), cross(w, ah)};
  const double l[3] = {norm2(d0), 2.0 * dot(d0, w), norm2(w)};
  double h[7] = {};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) h[i + j] += f[i] * f[j];
  for (int i = 0; i < 3; ++i) h[i] -= radius * radius * l[i];
  double roots[16];  // 6 + 3 + 3 at most (16: std::sort's insertion threshold, for -Warray-bounds)
  int n = real_roots_in(h, 6, 0.0, t_max, roots);
  // Between consecutive roots of h neither side's gap (side * distance - radius) changes sign: read
  // the distance at the midpoints and take the first fall of either gap from outside to inside with
  // the foot on the segment. Both sides count: the disc may pass the line beyond an end and meet
  // the other face later, the wall turning back onto it.
  // Touching and receding: until the gap has grown past the round-off of the distance (some ulps
  // of the positions), a "fall" read there is noise (a disc bounced off an arm it rides with got
  // one at 1e-19 s, for ever); roots of h before then are no knots.
  double t_skip = 0.0;
  {
    const double noise = 0x1p-46 * (norm(rel) + norm(d0) + radius);
    const double rate = side0 * c.distance_rate0();
    if (side0 * c.distance(0.0) - radius <= noise && rate > 0.0) t_skip = noise / rate;
  }
  double knots[18];
  auto make_knots = [&] {
    int nk = 0;
    knots[nk++] = 0.0;
    for (int k = 0; k < n; ++k)
      if (roots[k] > knots[nk - 1] && roots[k] > t_skip && roots[k] < t_max) knots[nk++] = roots[k];
    knots[nk++] = t_max;
    return nk;
  };
  int nk = make_knots();
  double found = kNever;
  double prev_mid = 0.0;
  double prev_dist = c.distance(0.0);
  for (int k = 0; k + 1 < nk && found == kNever; ++k) {
    const double mid = knots[k] + 0.5 * (knots[k + 1] - knots[k]);
    const double dist = c.distance(mid);
    for (double side : {1.0, -1.0}) {
      if (!(side * prev_dist - radius > 0.0 && side * dist - radius < 0.0)) continue;
      // Bisect that gap itself between the two midpoints: exactly one sign change lies there.
      double lo = prev_mid, hi = mid;
      for (int it = 0; it < 200; ++it) {
        const double m = lo + 0.5 * (hi - lo);
        if (m <= lo || m >= hi) break;
        (side * c.distance(m) - radius >= 0.0 ? lo : hi) = m;
      }
      if (c.foot_on_segment(lo)) {
        found = lo;
        break;
      }
    }
    prev_mid = mid;
    prev_dist = dist;
  }
  // (A fall at t_max itself, the last root at the horizon, is left to the next prediction.)
  // The other way into an overlap: the foot comes onto the segment over an end while the gap is
  // <= 0. Anywhere but at a pivot the disc would overlap that end, which is met first; at the
  // pivot of a turning arm a disc touching the end stays touching it while the line sweeps round
  // onto it, and its gap is exactly 0 there (a double root of h). Those instants are roots of h or
  // of the foot's q = dot(Y, D) = 0 or |D|^2 (cubics at most): with them as knots, whether the disc
  // overlaps the segment is the same over each interval between knots.
  const double q0[4] = {dot(rel, d0), dot(v, d0) + dot(rel, w), dot(ah, d0) + dot(v, w), dot(ah, w)};
  const double q1[4] = {q0[0] - l[0], q0[1] - l[1], q0[2] - l[2], q0[3]};
  n += real_roots_in(q0, 3, 0.0, t_max, roots + n);
  n += real_roots_in(q1, 3, 0.0, t_max, roots + n);
  std::sort(roots, roots + n);
  nk = make_knots();
  prev_mid = 0.0;
  for (int k = 0; k + 1 < nk && knots[k] < found; ++k) {
    const double mid = knots[k] + 0.5 * (knots[k + 1] - knots[k]);
    for (double side : {1.0, -1.0}) {
      // Not overlapping before, and not outside the line's strip either (that is a fall, above).
      if (!c.overlaps(mid, side) || c.overlaps(prev_mid, side) || side * c.distance(prev_mid) - radius > 0.0) continue;
      double lo = prev_mid, hi = mid;
      for (int it = 0; it < 200; ++it) {
        const double m = lo + 0.5 * (hi - lo);
        if (m <= lo || m >= hi) break;
        (c.overlaps(m, side) ? hi : lo) = m;
      }
      // Only at the contact distance (the pivot's case, within the overlap budget): a disc passing
      // an end deeper than that meets the end, which is the end's contact, not this one's.
      if (side * c.distance(lo) - radius < -1e-9 * radius) continue;
      return std::min(lo, found);
    }
    prev_mid = mid;
  }
  return found;
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
