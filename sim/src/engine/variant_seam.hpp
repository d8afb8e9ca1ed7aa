// SPDX-License-Identifier: MIT
// The seam between the table of variants (factory.cpp) and the translation units that compile
// them: one function per row, explicitly instantiated in a unit of its own (engine.hpp's
// TURTLEGAS_ENGINE_VARIANT), so that the factory needs no engine code and the build parallelises.
#pragma once

#include <memory>
#include <vector>

#include "engine_base.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim::detail {

/// The words of the table's columns.
namespace variant {
inline constexpr bool balls_meet = true;   ///< balls collide with each other
inline constexpr bool balls_pass = false;  ///< they pass through each other (effects.ball_ball false)
inline constexpr bool exact = false;       ///< exact (event-driven) mode
inline constexpr bool step = true;         ///< step mode, the memo's algorithm
inline constexpr bool plain = false;       ///< no turtles, collision layers or moving walls
inline constexpr bool extras = true;       ///< some of them
}  // namespace variant

/// Builds the engine variant for `def`; see engine.hpp for `release`.
template <class Flight, bool kBallBall, bool kStep, bool kExtras>
std::unique_ptr<EngineBase> make_variant(const WorldDef& def, std::vector<BallDef>* release);

}  // namespace turtlegas::sim::detail
