// SPDX-License-Identifier: MIT
// Controller plugins (`--plugin`): shared modules that add controllers to the registry.
#pragma once

#include <string>
#include <vector>

#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

/// Loads controller plugins: shared modules exporting `extern "C" void turtlegas_register(Registry&)`,
/// built against the same turtlegas headers and compiler (see docs/controllers.md). They stay loaded
/// for the life of the program, since the registry holds their code. BadInput for a file that is
/// not such a plugin.
void load_plugins(const std::vector<std::string>& paths, turtle::Registry& registry);

}  // namespace turtlegas::apps
