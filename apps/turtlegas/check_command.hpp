// SPDX-License-Identifier: MIT
// `turtlegas check WORLD.json...`: load, validate and build worlds in both modes.
#pragma once

#include <string>
#include <vector>

#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

/// Checks each file in turn: one summary line (and the turtles' line) on stdout for a good one,
/// the error on stderr for a bad one, and goes on with the next. Returns exit_ok when every file is
/// good, exit_bad_input when one is bad (exit_failure when one failed otherwise); with more than
/// one file, a last line counts them.
int check_command(const std::vector<std::string>& files, const turtle::Registry& registry);

}  // namespace turtlegas::apps
