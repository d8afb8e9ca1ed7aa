// SPDX-License-Identifier: MIT
// The world file's `game` key.
#pragma once


#include <nlohmann/json.hpp>

#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/tag_game.hpp"
#include "turtlegas/world/json_read.hpp"

namespace turtlegas::world {

/// Reads `"game": {"kind": "tag", "it": "t1", "no_tag_back": 2.0}` (def's turtles already read),
/// failing through `reader` (the world file's).
turtle::TagRules read_game(const nlohmann::json& game, const sim::WorldDef& def, const JsonReader& reader);

}  // namespace turtlegas::world
