// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <limits>

#include "turtlegas/sim/roots.hpp"
#include "turtlegas/sim/toi.hpp"
#include "turtlegas/sim/vec2.hpp"
#include "turtlegas/sim/world_def.hpp"

// Ray casts: the first thing a ray from a point meets, for range sensors. A ray is a disc of
// radius 0 flying at unit speed, so its distances are the engine's times of impact with r = 0,
// in the same cancellation-free arrangements (docs/physics.md, "Rays"). World::cast_ray walks the
// engine's grid cell by cell along the ray and stops at the first hit proven nearest.
namespace turtlegas::sim {

/// What a ray can hit.
enum class RayTarget : std::uint8_t { none, wall, wall_end, ball, turtle };

/// A ray from `origin` along `dir`, seen with `layers`: it meets what those layers collide with
/// (Layers::collides_with; a wall that is not there, or not there for these layers, and a body in
/// no category the mask names are not seen).
struct Ray {
  Vec2 origin;     ///< world units
  Vec2 dir{0, 1};  ///< any non-zero vector (normalised by the cast)
  double range = kNever;  ///< world units >= 0; hits farther away are not reported (finite in a periodic arena)
  Layers layers{};
  /// A turtle the ray does not see (the sensing turtle itself), or kNoTurtle.
  std::uint32_t self = std::numeric_limits<std::uint32_t>::max();
  static constexpr std::uint32_t kNoTurtle = std::numeric_limits<std::uint32_t>::max();
};

/// The first hit of a ray.
struct RayHit {
  double distance = kNever;  ///< world units along the ray; kNever when nothing is within range
  RayTarget target = RayTarget::none;
  std::uint32_t index = 0;   ///< the ball, turtle or wall index (a wall end: the first wall that owns it)
  bool hit() const { return target != RayTarget::none; }
};

/// Distance along unit vector u from a ray's origin to a disc of radius r whose centre is at
/// rel = centre - origin: 0 when the origin is inside or on the disc, kNever when the ray misses,
/// is tangent or points away. The root (b - sqrt(r^2 - c^2)) with b = rel.u, c = rel x u is
/// written as (|rel|^2 - r^2) / (b + sqrt((r - |c|)(r + |c|))): nothing cancels for a far disc or a
/// near-tangent ray.
inline double ray_disc(Vec2 rel, Vec2 u, double r) {
  const double gap = norm2(rel) - r * r;
  if (gap <= 0.0) return 0.0;
  const double b = dot(rel, u);
  if (b <= 0.0) return kNever;
  const double c = std::fabs(cross(rel, u));
  const double disc = (r - c) * (r + c);
  if (!(disc > 0.0)) return kNever;  // a miss, or tangent: a graze is no hit
  return gap / (b + std::sqrt(disc));
}

/// Distance along unit vector u from a ray's origin at rel = origin - s.p1 to the segment s (ends
/// included): the line is crossed at -h / (u.n) with h = rel.n, the origin's signed distance to it;
/// kNever when the ray runs parallel to the line or away from it, or crosses it off the segment.
/// An origin on the segment is a hit at 0. (A ray along the wall's own line meets an end first:
/// ray_point.)
inline double ray_segment(Vec2 rel, Vec2 u, const Segment& s) {
  const double h = dot(rel, s.n);
  const double un = dot(u, s.n);
  double d = 0.0;
  if (h != 0.0) {
    if (un == 0.0 || (h > 0.0) == (un > 0.0)) return kNever;
    d = -h / un;
  }
  const double foot = dot(rel, s.u) + d * dot(u, s.u);
  if (!(foot >= 0.0 && foot <= s.len)) return kNever;
  return d;
}

/// Distance along unit vector u from a ray's origin at rel = origin - p to the point p: only a
/// ray exactly through it hits (a point has no width), which is how a ray along a wall's line
/// meets the wall's end.
inline double ray_point(Vec2 rel, Vec2 u) {
  if (cross(rel, u) != 0.0) return kNever;
  const double b = -dot(rel, u);
  return b >= 0.0 ? b : kNever;
}

}  // namespace turtlegas::sim
