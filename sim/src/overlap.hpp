// SPDX-License-Identifier: MIT
// The overlap measure (World::measure_overlap): how deep the deepest overlap of the scene is.
// Production code, independent of the engine's own grid; the test oracles are in reference.hpp.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "turtlegas/sim/toi.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim::detail {

/// Discs as the overlap check reads them: n of them, each read through these functions (so that
/// an engine need not copy its million bodies into arrays to be checked).
struct DiscView {
  std::size_t n = 0;
  std::function<Vec2(std::size_t)> pos;
  std::function<double(std::size_t)> radius;
  std::function<bool(std::size_t)> alive;
};

/// Deepest overlap among discs (ball-ball) and between discs and segments, found with a grid of
/// sorted cell keys built from scratch (independent of the engine's grid; 28 bytes per disc while it
/// runs, 40 for a gas spread past 2^30 cells).
/// Periodic arenas use the minimum image when width/height are > 0. ball_pairs false checks discs
/// against walls only. With layers given, pairs whose collision layers do not meet are skipped
/// (they may overlap).
Overlap deepest_overlap(const DiscView& discs, const std::vector<Segment>& walls, double periodic_width = 0.0,
                        double periodic_height = 0.0, bool ball_pairs = true,
                        const std::vector<Layers>* body_layers = nullptr, const std::vector<Layers>* wall_layers = nullptr);

}  // namespace turtlegas::sim::detail
