// SPDX-License-Identifier: MIT
// A gas engine's saved state (sim/engine_state.hpp) as JSON, format turtlegas-engine-state/1: what
// a checkpoint carries so that `run --resume` goes on from it without replaying (docs/cli.md,
// "Checkpoints"). Every double is written so that it reads back to the same bits: a JSON number
// in the shortest form that round-trips (17 significant digits at most), and the infinities the
// engine keeps for "never" as the strings "inf" and "-inf".
#pragma once

#include <nlohmann/json.hpp>

#include "turtlegas/sim/engine_state.hpp"

namespace turtlegas::formats {

nlohmann::json engine_state_json(const sim::EngineState& state);
/// Reads one back; std::invalid_argument naming the JSON path of what is wrong.
sim::EngineState engine_state_from_json(const nlohmann::json& j);

}  // namespace turtlegas::formats
