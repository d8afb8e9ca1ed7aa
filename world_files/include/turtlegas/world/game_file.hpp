// SPDX-License-Identifier: MIT
// The world file's `game` key, and world servers that play the scene's game.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/game.hpp"
#include "turtlegas/turtle/tag_game.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::world {

struct Scene;

/// Reads `"game": {"kind": "tag", "it": "t1", "no_tag_back": 2.0}` (def's turtles already read).
/// `fail(json_path, reason)` must throw; it is called for every problem.
turtle::TagRules read_game(const nlohmann::json& game, const sim::WorldDef& def,
                           const std::function<void(const std::string&, const std::string&)>& fail);

/// The scene's game, ready for WorldServer::set_game; nullptr when the scene has none.
std::unique_ptr<turtle::Game> make_game(const Scene& scene);

/// A world server for the scene, playing its game. Throws as the WorldServer constructor does.
std::unique_ptr<turtle::WorldServer> make_server(const Scene& scene, const turtle::Registry& registry,
                                                 const turtle::ServerOptions& options);

}  // namespace turtlegas::world
