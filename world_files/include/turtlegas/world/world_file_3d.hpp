// SPDX-License-Identifier: MIT
// 3-D world files ("dimensions": 3, docs/worlds.md, "3-D worlds"): read into a sim::World3Def
// with the ids the event log and the state file use.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "turtlegas/sim/world3d.hpp"

namespace turtlegas::world {

struct World3File {
  std::string name;
  sim::World3Def def;
  std::vector<std::string> ball_ids;  ///< per sphere
  std::vector<std::string> wall_ids;  ///< per wall, the arena's six (arena-x0 ... arena-z1) last
};

/// Whether the text of a world file says "dimensions": 3 (false for any other text, including
/// invalid JSON: the 2-D loader then reports it).
bool is_world3_text(std::string_view text);
/// Reads a 3-D world file; throws WorldFileError(file, JSON path, reason).
World3File parse_world3(std::string_view text, std::string_view file_name);

}  // namespace turtlegas::world
