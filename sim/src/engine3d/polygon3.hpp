// SPDX-License-Identifier: MIT
// A convex planar wall in 3-D: its plane, edges and corners, and the contact kinds it has
// (docs/physics.md, "3-D"): the face (the memo's plane formula), an edge (a sphere against a
// segment: the cylinder around its line, valid where the foot lies on the segment) and a corner
// (the memo's wall-end formula, unchanged in 3-D).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "turtlegas/sim/toi3.hpp"
#include "turtlegas/sim/vec3.hpp"

namespace turtlegas::sim::detail {

struct Polygon3 {
  std::vector<Vec3> corners;
  std::vector<Vec3> along;   ///< unit edge directions, corner k to k + 1
  std::vector<double> length;
  std::vector<Vec3> inward;  ///< in-plane unit normals of the edges, towards the inside
  Vec3 normal;               ///< unit
  Vec3 lo, hi;               ///< bounding box
  double scale = 1.0;        ///< the largest edge, for tolerances

  explicit Polygon3(const std::vector<Vec3>& c) : corners(c) {
    const std::size_t n = c.size();
    Vec3 area;  // Newell's normal: robust for any convex polygon
    for (std::size_t k = 0; k < n; ++k) area += cross(c[k], c[(k + 1) % n]);
    normal = (1.0 / norm(area)) * area;
    lo = hi = c[0];
    scale = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const Vec3 e = c[(k + 1) % n] - c[k];
      const double l = norm(e);
      along.push_back((1.0 / l) * e);
      length.push_back(l);
      inward.push_back(cross(normal, along.back()));
      scale = std::max(scale, l);
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], c[k][a]);
        hi[a] = std::max(hi[a], c[k][a]);
      }
    }
  }
  /// Whether the projection of q on the plane lies inside (or on) the polygon, within tol.
  bool covers(Vec3 q, double tol) const {
    for (std::size_t k = 0; k < corners.size(); ++k)
      if (dot(q - corners[k], inward[k]) < -tol) return false;
    return true;
  }
  /// The nearest point of the polygon to q and its feature: 0 the face (q's foot inside), 1 an
  /// edge (index: from corner index to the next), 2 a corner.
  struct Nearest {
    Vec3 point;
    int kind = 0;
    std::uint32_t index = 0;
  };
  Nearest nearest(Vec3 q) const {
    if (covers(q, 0.0)) return {q - dot(q - corners[0], normal) * normal, 0, 0};
    Nearest best;
    double dist = kNever;
    const std::size_t n = corners.size();
    for (std::size_t e = 0; e < n; ++e) {
      const Vec3 de = q - corners[e];
      const double s = std::clamp(dot(de, along[e]), 0.0, length[e]);
      const Vec3 p = corners[e] + s * along[e];
      const double d = norm(q - p);
      if (d < dist) {
        dist = d;
        if (s > 0.0 && s < length[e]) best = {p, 1, static_cast<std::uint32_t>(e)};
        else best = {p, 2, static_cast<std::uint32_t>(s == 0.0 ? e : (e + 1) % n)};
      }
    }
    return best;
  }
  /// The distance from q to the polygon: to its plane where q's foot falls inside, else to the
  /// nearest edge.
  double distance(Vec3 q) const {
    double dist = covers(q, 0.0) ? std::abs(dot(q - corners[0], normal)) : kNever;
    for (std::size_t e = 0; e < corners.size(); ++e) {
      const Vec3 de = q - corners[e];
      const double s = std::clamp(dot(de, along[e]), 0.0, length[e]);
      dist = std::min(dist, norm(de - s * along[e]));
    }
    return dist;
  }
};

}  // namespace turtlegas::sim::detail
