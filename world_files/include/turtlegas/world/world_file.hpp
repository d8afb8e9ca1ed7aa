// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/tag_game.hpp"
#include "turtlegas/turtle/world_server.hpp"
#include "turtlegas/world/expect.hpp"

namespace turtlegas::world {

/// The format string a world file must declare in its "format" key.
inline constexpr std::string_view world_format = "turtlegas-world/1";

/// A world file that cannot be used. what() is one line:
/// `FILE: /balls/3/radius: radius must be > 0 (got -1)`, `FILE: MESSAGE` when no JSON path applies,
/// or `FILE:LINE:COLUMN: invalid JSON: ...` for a syntax error.
struct WorldFileError : std::runtime_error {
  WorldFileError(std::string file, std::string json_path, std::string reason, std::size_t line = 0,
                 std::size_t column = 0);

  std::string file;       ///< the file name as given (for messages)
  std::string json_path;  ///< JSON pointer to the offending value (`/balls/3/radius`), or empty
  std::string reason;     ///< the message without the file and path prefix
  std::size_t line = 0;   ///< 1-based, for JSON syntax errors only (0 otherwise)
  std::size_t column = 0; ///< 1-based, in bytes, for JSON syntax errors only (0 otherwise)
};

/// A world file's contents: the bodies, and the program that drives each turtle.
struct Scene {
  sim::WorldDef def;  ///< accepted by sim::validate; turtles' angles in radians
  /// programs[i] drives def.turtles[i]; controllers are registered, sensor arcs in degrees.
  std::vector<turtle::TurtleProgram> programs;
  /// The world's game (the `game` key): the tag rules, when the world plays tag.
  std::optional<turtle::TagRules> game;
  /// The `expect` list of a scripted test world (empty when the file has none).
  Expectations expect;
};

/// Reads and checks a `turtlegas-world/1` file, generates its gases and returns a scene that
/// sim::validate accepts and turtle::WorldServer can run with `registry`: every turtle's controller
/// is registered there, and the `script` controller's commands are checked. Throws WorldFileError
/// (also for a file that cannot be read).
Scene load_scene(const std::filesystem::path& file, const turtle::Registry& registry);

/// As load_scene, from text already in memory; file_name is used in messages and as the default
/// scene name (its stem).
Scene parse_scene(std::string_view text, std::string_view file_name, const turtle::Registry& registry);

/// The bodies only: load_scene(file).def, with controller names left unchecked (no registry is
/// given; `script` commands are still checked).
sim::WorldDef load_world_file(const std::filesystem::path& file);

/// As load_world_file, from text already in memory.
sim::WorldDef parse_world(std::string_view text, std::string_view file_name);

}  // namespace turtlegas::world
