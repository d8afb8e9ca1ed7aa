// SPDX-License-Identifier: MIT
// The state file (design.md, "--state-out"): a world's bodies at its current time,
//   {"t": T, "balls": [{"id": "b1", "pos": [x, y], "vel": [u, v]}],
//    "turtles": [{"id": "t1", "pos": [x, y], "heading": h}]}
// live balls only; headings in degrees, Logo convention, in [0, 360).
#pragma once

#include <ostream>

#include "turtlegas/formats/names.hpp"
#include "turtlegas/sim/world.hpp"

namespace turtlegas::formats {

/// Writes the state of `world`, its bodies named by `names` (ball and turtle ids), in pieces of
/// about a megabyte (a million balls need not be in memory as text at once).
void write_state(std::ostream& out, const sim::World& world, const RunNames& names);

}  // namespace turtlegas::formats
