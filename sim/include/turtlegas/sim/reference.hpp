// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "turtlegas/sim/events.hpp"
#include "turtlegas/sim/toi.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"

// Slow, obviously-correct references that tests cross-check the engine against.
namespace turtlegas::sim::reference {

/// Discs as the overlap check reads them: n of them, each read through these functions (so that
/// an engine need not copy its million bodies into arrays to be checked).
struct DiscView {
  std::size_t n = 0;
  std::function<Vec2(std::size_t)> pos;
  std::function<double(std::size_t)> radius;
  std::function<bool(std::size_t)> alive;
};

/// Deepest overlap among discs (ball-ball) and between discs and segments, found with a grid of
/// sorted cell keys built from scratch (independent of the engine's grid; 4 bytes per disc).
/// Periodic arenas use the minimum image when width/height are > 0. ball_pairs false checks discs
/// against walls only. With layers given, pairs whose collision layers do not meet are skipped
/// (they may overlap).
Overlap overlap(const DiscView& discs, const std::vector<Segment>& walls, double periodic_width = 0.0,
                double periodic_height = 0.0, bool ball_pairs = true, const std::vector<Layers>* body_layers = nullptr,
                const std::vector<Layers>* wall_layers = nullptr);

/// The same for discs in arrays.
Overlap overlap(const std::vector<Vec2>& pos, const std::vector<double>& radius,
                const std::vector<bool>& alive, const std::vector<Segment>& walls,
                double periodic_width = 0.0, double periodic_height = 0.0, bool ball_pairs = true,
                const std::vector<Layers>* body_layers = nullptr, const std::vector<Layers>* wall_layers = nullptr);

/// Exact-mode events up to t_end found by brute force: every pair and every wall checked after
/// every event, O(N^2) per event, no grid, no event queue. Same contact rules as the engine.
/// Boundaries `none` and `walls` only. Returns the events and leaves final states in *final.
std::vector<Event> events(const WorldDef& def, double t_end, std::vector<BallState>* final = nullptr);

/// Where a ball is at time t (seconds) when it flies alone (no other ball, no wall but the arena's)
/// in an arena with `Boundary::walls`, elastic, under gravity (0, -g), g > 0 in units/s^2: x
/// reflects between the side walls (the line x0 + vx t folded into [r, width - r]), y is a
/// parabola bouncing on the floor y = r. The closed form that step mode's error is measured
/// against. Throws std::invalid_argument unless g > 0, the ball starts inside [r, width - r] x
/// [r, height - r], is not at rest on the floor (the engine models resting by hops of t_c, see
/// docs/physics.md) and its apex stays below the ceiling's contact height - r.
BallState ballistic(const BallDef& ball, const ArenaDef& arena, double g, double t);

}  // namespace turtlegas::sim::reference
