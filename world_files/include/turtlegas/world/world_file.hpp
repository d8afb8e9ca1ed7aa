// SPDX-License-Identifier: MIT
// Reading `turtlegas-world/1` files into scenes (docs/worlds.md is the format's reference).
#pragma once

#include <filesystem>
#include <string_view>

#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/world/file_error.hpp"
#include "turtlegas/world/scene.hpp"

namespace turtlegas::world {

/// The format string a world file must declare in its "format" key.
inline constexpr std::string_view world_format = "turtlegas-world/1";

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
