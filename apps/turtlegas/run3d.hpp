// SPDX-License-Identifier: MIT
// `turtlegas run` and `check` of a 3-D world ("dimensions": 3; docs/worlds.md, "3-D worlds"):
// the event log, the state file and the stats of the 3-D engine (sim/world3d.hpp).
#pragma once

#include <optional>
#include <string>

#include "run_command.hpp"
#include "turtlegas/world/world_file_3d.hpp"

namespace turtlegas::apps {

/// The 3-D world in `file`, or nothing when the file is not a 3-D world (the 2-D loader then
/// reads it and reports its errors). A bad 3-D world is BadInput.
std::optional<world::World3File> load_world3_if_3d(const std::string& file);
int run3d(const RunOptions& opt, const world::World3File& w);
int check3d(const std::string& file, const world::World3File& w);
/// `render WORLD3D.json --at T --out F.svg|F.png`: the world at T seen along -z (orthographic),
/// `width_px` across the arena's longer side, spheres shaded by depth (nearer: lighter, on top).
int render3d(const std::string& file, double at, const std::string& out, double width_px, const world::World3File& w);

}  // namespace turtlegas::apps
