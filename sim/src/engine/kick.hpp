// SPDX-License-Identifier: MIT
// Step mode's field: the memo's velocity kick between steps. Step mode flies every body straight
// inside a step and lets the fields act only at the step's end, so it needs no flight of its own:
// the kick is a run-time value, and a new field adds a term here, never a template.
#pragma once

#include <cstdint>
#include <map>
#include <tuple>
#include <vector>

#include "turtlegas/sim/field_flight.hpp"
#include "turtlegas/sim/vec2.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim::detail {

/// The velocity change of a step of length dt for every ball at the end of each step (turtles feel
/// no field): v += dt g for an uncharged ball; for a charged one the exact velocity flow of the
/// step under a = g + (q/m) E and w = q Bz / m with the position held, field_kick: the rotation of
/// v by -w dt combined with the acceleration. Species of equal (a, w) are kept by ball index, only
/// when some charged ball feels a field. The step is drift (straight, the step's old velocity)
/// then kick: a Lie splitting, first order in dt (docs/physics.md, "Step mode under fields").
class Kick {
 public:
  Kick() = default;
  explicit Kick(const WorldDef& def) : a_(def.effects.gravity) {
    const EffectsDef& fx = def.effects;
    if (fx.electric == Vec2{} && fx.magnetic == 0.0) return;
    bool charged = false;
    for (const BallDef& b : def.balls) charged = charged || b.charge != 0.0;
    if (!charged) return;
    species_.push_back({fx.gravity, 0.0});
    of_.assign(def.balls.size(), 0);
    std::map<std::tuple<double, double, double>, std::uint32_t> index{{{fx.gravity.x, fx.gravity.y, 0.0}, 0}};
    for (std::size_t i = 0; i < def.balls.size(); ++i) {
      const BallDef& b = def.balls[i];
      if (b.charge == 0.0) continue;
      const double qm = b.charge / b.mass;
      const Species s{fx.gravity + qm * fx.electric, qm * fx.magnetic};
      const auto [it, added] = index.try_emplace({s.a.x, s.a.y, s.w}, static_cast<std::uint32_t>(species_.size()));
      if (added) species_.push_back(s);
      of_[i] = it->second;
    }
  }

  /// Whether the kick keeps something per ball (charged balls in a field): a run-time spawn refuses then.
  bool per_ball() const { return !of_.empty(); }
  /// Whether a kick changes any course: then "just collided, cannot meet again" no longer holds.
  bool changes_courses() const { return a_.x != 0.0 || a_.y != 0.0 || species_.size() > 1; }
  /// Ball `ball`'s velocity after the kick of a step of length dt.
  void apply(std::uint32_t ball, Vec2& v, double dt) const {
    if (of_.empty()) {
      v += dt * a_;
      return;
    }
    const Species& s = species_[of_[ball]];
    if (s.w == 0.0) v += dt * s.a;
    else v = field_kick(v, s.a, s.w, dt);
  }
  /// The potential energy per unit mass of a ball at x: -(g + (q/m) E).x.
  double potential(std::uint32_t ball, Vec2 x) const {
    return of_.empty() ? -dot(a_, x) : -dot(species_[of_[ball]].a, x);
  }

 private:
  struct Species {
    Vec2 a;
    double w = 0.0;
  };
  Vec2 a_{};
  std::vector<Species> species_;   ///< empty unless some charged ball feels a field; 0: uncharged
  std::vector<std::uint32_t> of_;  ///< each ball's species (likewise)
};

}  // namespace turtlegas::sim::detail
