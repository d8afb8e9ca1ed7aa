// SPDX-License-Identifier: MIT
// The cell-size policy: how wide the cells of the engine's table are for a scene.
#pragma once

#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim::detail {

/// The side of the table's cells for `def` run in `mode` (the grid may stretch it so that a whole
/// number of cells fit; see CellGrid):
///   - exact mode needs cells at least a diameter wide, so that touching bodies are always in
///     neighbouring cells; step mode needs the memo's rule, cells wider than any two bodies' radii
///     plus their paths in one step: 2 (largest radius + largest speed x dt);
///   - arena.cell, when given, is taken as it is, and must obey that rule (std::invalid_argument,
///     with the number and the remedies, otherwise);
///   - otherwise: in exact mode with balls that meet walls only (no ball-ball collisions, no
///     turtles) about one wall per cell (area / total length of the fixed walls), at most a
///     quarter of the arena; in every other case about 0.3 bodies per cell; then at least the rule
///     (by a relative 1e-9), the table under about 4e7 cells, and a periodic arena three cells
///     across (so that no pair is seen through two images) unless the rule forbids it.
/// A pure function of the scene: no state, tested on its own (tests/sim/cell_size_test.cpp).
double choose_cell_size(const WorldDef& def, Mode mode);

}  // namespace turtlegas::sim::detail
