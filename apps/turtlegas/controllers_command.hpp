// SPDX-License-Identifier: MIT
// `turtlegas controllers`: the controllers world files can name, with their params.
#pragma once

#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

/// One line per registered controller: its name and summary.
int controllers_command(const turtle::Registry& registry);

}  // namespace turtlegas::apps
