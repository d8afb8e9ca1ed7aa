// SPDX-License-Identifier: MIT
// One ball or turtle entry of a world file, read alone: for bodies spawned into a running world
// (the protocol's `spawn`, an input log's spawn line), with the world file's keys, defaults and
// checks (docs/world-format.md).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::world {

/// A ball entry ({"id": ..., "pos": [x, y], "vel": ..., "radius": ..., "mass": ...}). Throws
/// WorldFileError whose json_path is relative to the entry (`/radius`), `file` naming the source.
/// Spawned bodies are in the default collision category: "category" and "collides_with" are
/// refused (the world's category names are the world file's).
sim::BallDef read_ball_entry(const nlohmann::json& entry, const std::string& file);

struct TurtleEntry {
  sim::TurtleDef body;
  turtle::TurtleProgram program;
};
/// A turtle entry, its controller checked against `registry`. Without "controller" the turtle is
/// remote (whoever spawns a turtle at run time usually means to drive it), unlike in a world file.
TurtleEntry read_turtle_entry(const nlohmann::json& entry, const std::string& file, const turtle::Registry& registry);

/// Spawns the body of `spawn`, {"ball": {...}} or {"turtle": {...}} (the protocol's and the input
/// log's shape), into `server` at its current boundary (WorldServer::spawn_ball, spawn_turtle).
/// Throws WorldFileError (json_path under /ball or /turtle) for an entry that is not one, and
/// std::invalid_argument for a spawn the server refuses. Returns the new body's index.
std::size_t spawn_entry(turtle::WorldServer& server, const nlohmann::json& spawn, const std::string& file,
                        const turtle::Registry& registry);

}  // namespace turtlegas::world
