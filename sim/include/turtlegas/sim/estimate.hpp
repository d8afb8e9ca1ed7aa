// SPDX-License-Identifier: MIT
// What a run of a scene will cost, from its scales alone (no engine is built): for `check`'s
// warnings ("this scene predicts 1e15 collisions"), and for anyone sizing a run.
#pragma once

#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim {

/// Orders of magnitude, per simulated second and for a run to `until`. Every figure is finite
/// (a scale that overflows gives the largest double) and >= 0.
struct WorkEstimate {
  double max_speed = 0.0;         ///< the fastest body's speed after falling across the arena
  double collisions_per_s = 0.0;  ///< balls with walls and with each other (exact mode's events)
  double crossings_per_s = 0.0;   ///< exact mode's cell crossings
  double steps_per_s = 0.0;       ///< step mode: 1 / dt
  double events = 0.0;            ///< the mode's events for the whole run (collisions + crossings, or
                                  ///< steps + collisions)
};

/// The estimate for `def` run in `mode` to time `until` (see docs/physics.md, "What a run costs").
/// Kinetic theory, not a simulation: a dilute-gas collision rate (2 sigma n v per ball, sigma the
/// contact distance, n the number density), walls met at v / L (L the arena's smaller side), cell
/// crossings at v / cell, speeds raised by what gravity adds across the arena. Expect it within a
/// factor of a few of the truth for gases; it is meant to tell 1e6 from 1e15.
WorkEstimate estimate_work(const WorldDef& def, Mode mode, double until);

}  // namespace turtlegas::sim
