// SPDX-License-Identifier: MIT
// A world file's contents, and the world servers that run them (playing the scene's game).
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/game.hpp"
#include "turtlegas/turtle/tag_game.hpp"
#include "turtlegas/turtle/world_server.hpp"
#include "turtlegas/world/expect.hpp"

namespace turtlegas::world {

/// A world file's contents: the bodies, and the program that drives each turtle.
struct Scene {
  sim::WorldDef def;  ///< accepted by sim::validate; turtles' angles in radians
  /// programs[i] drives def.turtles[i]; controllers are registered, sensor arcs in degrees.
  std::vector<turtle::TurtleProgram> programs;
  /// The world's game (the `game` key): the tag rules, when the world plays tag.
  std::optional<turtle::TagRules> game;
  /// What cameras see: the walls', balls' and turtles' "colour" keys (WorldServer::set_colours).
  turtle::Colours colours;
  /// The `views` list (display windows, turtle/view.hpp); follows name turtles of def.
  std::vector<turtle::View> views;
  /// The `expect` list of a scripted test world (empty when the file has none).
  Expectations expect;
};

/// The scene's game, ready for WorldServer::set_game; nullptr when the scene has none.
std::unique_ptr<turtle::Game> make_game(const Scene& scene);

/// A world server for the scene, playing its game. Throws as the WorldServer constructor does.
std::unique_ptr<turtle::WorldServer> make_server(const Scene& scene, const turtle::Registry& registry,
                                                 const turtle::ServerOptions& options);

}  // namespace turtlegas::world
