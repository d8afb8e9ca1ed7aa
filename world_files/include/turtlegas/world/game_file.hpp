// SPDX-License-Identifier: MIT
// The world file's `game` key.
#pragma once

#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/tag_game.hpp"

namespace turtlegas::world {

/// Reads `"game": {"kind": "tag", "it": "t1", "no_tag_back": 2.0}` (def's turtles already read).
/// `fail(json_path, reason)` must throw; it is called for every problem.
turtle::TagRules read_game(const nlohmann::json& game, const sim::WorldDef& def,
                           const std::function<void(const std::string&, const std::string&)>& fail);

}  // namespace turtlegas::world
