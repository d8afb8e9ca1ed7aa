// SPDX-License-Identifier: MIT
// The elastic wedge, folded: the exact limit of a zero-time sequence of elastic reflections
// between two obstacles that a body touches at one instant (docs/physics.md, "The elastic wedge").
//
// A disc that touches two obstacles at once (two walls meeting at an angle alpha < 90 degrees: its
// centre at the apex of the lines offset by its radius) is reflected by each in turn, at that one
// instant, for as long as it approaches one of them. In the frame of the velocity v* that moves
// with both contacts (v* . n_k = u_k . n_k; v* = 0 for standing walls), each reflection is the
// mirror w -> w - 2 (w . n) n, so a pair of them turns w by twice the angle between the normals:
// by 2 alpha, modulo a turn. The body leaves when w lies in the cone that leaves both (w . n_A >= 0
// and w . n_B >= 0, an arc of width alpha), which it reaches after at most about pi / alpha + 1
// reflections (the unfolding: the straight line through the apex crosses the images of the wedge
// once each). For alpha dividing pi a disc arriving along the bisector leaves with its velocity
// reversed, after pi / alpha reflections. The count and the outgoing angle follow from two first
// hits of a rotation on an arc, in closed form, so a wedge of 1e-5 degrees (1.8e7 reflections)
// costs what a 30-degree one does, and the speed |w| is kept to round-off (energy exact at e = 1).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "turtlegas/sim/vec2.hpp"

namespace turtlegas::sim::detail {

/// The outcome of fold(): the velocity after the sequence and how many reflections it took.
struct Folded {
  Vec2 v;
  std::uint64_t reflections = 0;
};

/// Angles within this of the leaving cone's edges count as inside it: the round-off of atan2 and
/// of the sums below (a few ulps of 2 pi); a velocity that close to tangent leaves at a rate below
/// 1e-12 of its speed, which the hold mark keeps from meeting the obstacle again.
inline constexpr double kFoldAngle = 1e-12;

/// The elastic reflections of velocity v0 (already reflected by obstacle B, so it leaves B)
/// between obstacles A and B, A first: unit normals n_a, n_b from each obstacle towards the body
/// (n_a . n_b < 0, not parallel), surface velocities u_a, u_b. False when the two normals are
/// parallel (no cone to reach: the corridor, not a wedge).
inline bool fold(Vec2 v0, Vec2 n_a, Vec2 u_a, Vec2 n_b, Vec2 u_b, Folded& out) {
  constexpr double kPi = 3.14159265358979323846, kTwoPi = 2.0 * kPi;
  const double det = cross(n_a, n_b);
  if (!(std::abs(det) > 0.0)) return false;
  const double ca = dot(u_a, n_a), cb = dot(u_b, n_b);
  const Vec2 vstar{(ca * n_b.y - cb * n_a.y) / det, (cb * n_a.x - ca * n_b.x) / det};
  const Vec2 w = v0 - vstar;
  const double speed = norm(w);
  out = {v0, 0};
  if (!(speed > 0.0) || dot(w, n_a) >= 0.0) return true;  // it leaves A too: nothing to fold
  // Angles measured from n_a. d: n_b's angle; the cone leaving both is [lo, lo + width].
  const double d = std::atan2(cross(n_a, n_b), dot(n_a, n_b));
  // The wedge's angle, pi - |d|, from its own sine and cosine: exact to its own ulps however small
  // it is (pi - |d| would carry the ulps of pi, 4e-16, which 9e6 steps below make 4e-9).
  const double width = std::atan2(std::abs(cross(n_a, n_b)), -dot(n_a, n_b));
  const double lo = d > 0.0 ? d - kPi / 2 : -kPi / 2;
  const double theta0 = std::atan2(cross(n_a, w), dot(n_a, w));
  // A reflection across the line normal to n (angle phi) maps theta to pi + 2 phi - theta. With
  // phi_a = 0 and phi_b = d: the even terms (after B, A B, A B A B, ...) are theta0 + j delta, the
  // odd ones (after A, A B A, ...) theta1 - j delta, with delta = 2 d and theta1 = pi - theta0.
  const double delta = d > 0.0 ? -2.0 * width : 2.0 * width;  // 2 d, modulo a turn
  constexpr std::uint64_t kNever = std::numeric_limits<std::uint64_t>::max();
  // The first j >= 0 at which start + j step (step != 0) lies in the cone, or kNever if it passes
  // the cone in its first turn (then the other sequence gets there first: the unfolding).
  auto first_hit = [&](double start, double step) -> std::uint64_t {
    double x = std::fmod(start - lo, kTwoPi);  // from the cone's start, counter-clockwise, in [0, 2 pi)
    if (x < 0.0) x += kTwoPi;
    if (x <= width + kFoldAngle || x >= kTwoPi - kFoldAngle) return 0;
    double j = 0.0;
    if (step > 0.0) {
      j = std::ceil((kTwoPi - x - kFoldAngle) / step);
      if (x + j * step > kTwoPi + width + kFoldAngle) return kNever;
    } else {
      j = std::ceil((x - width - kFoldAngle) / -step);
      if (x + j * step < -kFoldAngle) return kNever;
    }
    return static_cast<std::uint64_t>(std::max(j, 0.0));
  };
  const double theta1 = kPi - theta0;
  const std::uint64_t je = first_hit(theta0, delta), jo = first_hit(theta1, -delta);
  if (je == kNever && jo == kNever) return false;
  const std::uint64_t ke = je == kNever ? kNever : 2 * je, ko = jo == kNever ? kNever : 2 * jo + 1;
  double theta = 0.0;
  if (ke <= ko) out.reflections = ke, theta = theta0 + static_cast<double>(je) * delta;
  else out.reflections = ko, theta = theta1 - static_cast<double>(jo) * delta;
  // Back to the plane: n_a's direction turned by theta, at the speed w had.
  const double c = std::cos(theta), s = std::sin(theta);
  out.v = vstar + speed * Vec2{c * n_a.x - s * n_a.y, s * n_a.x + c * n_a.y};
  return true;
}

}  // namespace turtlegas::sim::detail
