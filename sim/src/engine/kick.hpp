// SPDX-License-Identifier: MIT
// Step mode's field: the memo's velocity kick between steps. Step mode flies every body straight
// inside a step and lets the fields act only at the step's end, so it needs no flight of its own:
// the kick is a run-time value, and a new field adds a term here, never a template.
#pragma once

#include <cstdint>

#include "turtlegas/sim/vec2.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim::detail {

/// v += dt a for every ball at the end of each step (turtles feel no field). A magnetic field
/// would rotate v by -W dt here, and charges would scale the terms by each ball's q/m (kept, like
/// a flight's, by ball index and only when a scene has them).
class Kick {
 public:
  Kick() = default;
  explicit Kick(const EffectsDef& fx) : a_(fx.gravity) {}

  /// Whether a kick changes any course: then "just collided, cannot meet again" no longer holds.
  bool changes_courses() const { return a_.x != 0.0 || a_.y != 0.0; }
  /// Ball `ball`'s velocity after the kick of a step of length dt.
  void apply(std::uint32_t /*ball*/, Vec2& v, double dt) const { v += dt * a_; }
  /// The potential energy per unit mass of a ball at x.
  double potential(std::uint32_t /*ball*/, Vec2 x) const { return -dot(a_, x); }

 private:
  Vec2 a_{};
};

}  // namespace turtlegas::sim::detail
