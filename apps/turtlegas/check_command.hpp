// SPDX-License-Identifier: MIT
// `turtlegas check WORLD.json`: load, validate and build a world in both modes.
#pragma once

#include <string>

#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

/// Prints one summary line (and the turtles' line) on stdout; exit_ok, or throws BadInput.
int check_command(const std::string& file, const turtle::Registry& registry);

}  // namespace turtlegas::apps
