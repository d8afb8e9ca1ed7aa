// SPDX-License-Identifier: MIT
// A disc on a field flight and a wall: a face (the segment's interior, either side) and a point
// (a wall's end).
#include <algorithm>
#include <cmath>

#include "detail.hpp"
#include "turtlegas/sim/field_toi.hpp"

namespace turtlegas::sim {
using namespace field_toi_detail;
namespace {

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

}  // namespace

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

}  // namespace turtlegas::sim
