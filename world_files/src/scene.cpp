// SPDX-License-Identifier: MIT
#include "turtlegas/world/scene.hpp"

namespace turtlegas::world {

std::unique_ptr<turtle::Game> make_game(const Scene& scene) {
  if (!scene.game) return nullptr;
  return std::make_unique<turtle::TagGame>(*scene.game);
}

std::unique_ptr<turtle::WorldServer> make_server(const Scene& scene, const turtle::Registry& registry,
                                                 const turtle::ServerOptions& options) {
  auto server = std::make_unique<turtle::WorldServer>(scene.def, scene.programs, registry, options);
  if (auto game = make_game(scene)) server->set_game(std::move(game));
  server->set_views(scene.views);
  server->set_colours(scene.colours);
  return server;
}

}  // namespace turtlegas::world
