// SPDX-License-Identifier: MIT
// Mechanism 6 of the contacts room (contacts.hpp): the memo's restitution, with the TC rule that
// keeps an inelastic cluster from collapsing into infinitely many collisions in finite time, and
// the rest threshold that keeps a ball pressed onto an obstacle by a field from bouncing
// infinitely often (or sinking). docs/physics.md, "Responses" and "Flights and fields".
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "turtlegas/sim/vec2.hpp"

namespace turtlegas::sim::detail {

/// The memo's restitution ("2 replaced by 1 + e"), with the TC rule and the rest threshold.
struct Restitution {
  double e = 1.0;
  double tc = 0.0;
  bool inelastic = false;
  std::vector<double> last_time;  ///< per body, when it last changed course (only when e < 1)

  /// The TC rule (Luding & McNamara): a ball that collided less than tc ago collides elastically,
  /// so a cluster cannot collapse into infinitely many collisions in finite time.
  double for_ball(std::uint32_t i, double now) const { return now - last_time[i] < tc ? 1.0 : e; }
  double for_pair(std::uint32_t i, std::uint32_t j, double now) const {
    double out = e;
    if (inelastic) out = std::max(for_ball(i, now), for_ball(j, now));
    return out;
  }
  /// A ball's velocity v relative to an obstacle after bouncing off it; n is the unit contact
  /// normal pointing from the obstacle to the ball, a_n the field's acceleration of the ball along
  /// it, a_rest the same for the ball at rest (a_n without the magnetic part). Walls take the
  /// plain restitution: the TC rule is for ball clusters; a ball pressed onto a wall is kept from
  /// collapsing by the rest threshold.
  Vec2 bounce(Vec2 v, Vec2 n, double a_n, double a_rest) const {
    const double w = -dot(v, n);
    double w_out = e * w;
    // The rest threshold: a ball pressed onto the obstacle by the field leaves it at least fast
    // enough to stay away for tc. Without it an inelastic ball would bounce infinitely often before
    // coming to rest, and a ball at rest would sink.
    if (a_n < 0.0) {
      const double floor = -a_n * tc / 2.0;
      if (w_out < floor) {
        // An elastic bounce keeps the ball's energy: the normal speed the threshold asks for is
        // taken from the tangential speed (v turned, |v| kept) whenever |v| has that much. Only a
        // ball slower than the threshold is lifted with energy (a ball at rest would sink). Under
        // a strong field (q/m = 1e6 in E: floor ~ 10) adding it at every skipping bounce made
        // energy grow without bound.
        if (e == 1.0) return elastic_floor(v, n, w, floor, a_rest);
        w_out = floor;
      }
    }
    return v + (w + w_out) * n;
  }
  /// The elastic bounce below the threshold (bounce()): out of line, off the common path.
  [[gnu::cold]] Vec2 elastic_floor(Vec2 v, Vec2 n, double w, double floor, double a_rest) const {
    const Vec2 vt = v + w * n;  // the tangential part
    const double speed2 = dot(v, v), floor2 = floor * floor, vt2 = dot(vt, vt);
    if (speed2 > floor2 && vt2 > 0.0) return floor * n + std::sqrt((speed2 - floor2) / vt2) * vt;
    // Slower than the threshold, but faster than the threshold of a ball at rest (the pull
    // without its magnetic part, which a resting ball does not feel): all of its speed
    // along the normal, still without adding energy. Under a strong B the pull includes
    // W n.J(v), which grows with the speed itself (|W| tc / 2 = 1 at W = 2e4 asks for a
    // normal speed of |v_t|), and fast balls skipping along a wall were lifted with energy
    // (a mixed gas at q/m 1e6, Bz 0.01, gained 6e-5 of its energy in 200 events). Such a
    // ball leaves at least as fast as the resting threshold asks, so it stays away for about tc
    // against the rest of the pull, and B alone brings it back after about half a turn.
    const double rest_floor = -std::min(a_rest, 0.0) * tc / 2.0;
    if (speed2 > rest_floor * rest_floor) return std::sqrt(speed2) * n;
    return v + (w + floor) * n;
  }
};

}  // namespace turtlegas::sim::detail
