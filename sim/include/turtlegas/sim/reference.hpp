// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <vector>

#include "turtlegas/sim/events.hpp"
#include "turtlegas/sim/toi.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"

// Slow, obviously-correct references that tests cross-check the engine against.
namespace turtlegas::sim::reference {

/// Exact-mode events up to t_end found by brute force: every pair and every wall checked after
/// every event, O(N^2) per event, no grid, no event queue. Same contact rules as the engine.
/// Boundaries `none` and `walls` only. Returns the events and leaves final states in *final.
std::vector<Event> events(const WorldDef& def, double t_end, std::vector<BallState>* final = nullptr);

/// events() for balls on field flights (field_flight.hpp: gravity, the electric and the magnetic
/// field), elastic, every ball flown from its last event with field_advance and every pair, face
/// and end predicted by field_toi.hpp after every event: O(N^2) per event, no grid, no crossings,
/// no last-partner skip, no layers. Boundaries `none` and `walls` only.
std::vector<Event> field_events(const WorldDef& def, double t_end, std::vector<BallState>* final = nullptr);

/// Where a ball is at time t (seconds) when it flies alone (no other ball, no wall but the arena's)
/// in an arena with `Boundary::walls`, elastic, under gravity (0, -g), g > 0 in units/s^2: x
/// reflects between the side walls (the line x0 + vx t folded into [r, width - r]), y is a
/// parabola bouncing on the floor y = r. The closed form that step mode's error is measured
/// against. Throws std::invalid_argument unless g > 0, the ball starts inside [r, width - r] x
/// [r, height - r], is not at rest on the floor (the engine models resting by hops of t_c, see
/// docs/physics.md) and its apex stays below the ceiling's contact height - r.
BallState ballistic(const BallDef& ball, const ArenaDef& arena, double g, double t);

}  // namespace turtlegas::sim::reference
