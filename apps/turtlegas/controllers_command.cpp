// SPDX-License-Identifier: MIT
#include "controllers_command.hpp"

#include <algorithm>
#include <cstdio>
#include <string>

#include "cli_common.hpp"

namespace turtlegas::apps {

int controllers_command(const turtle::Registry& registry) {
  std::size_t width = 0;
  for (const std::string& name : registry.names()) width = std::max(width, name.size());
  for (const std::string& name : registry.names())
    std::printf("%-*s  %s\n", static_cast<int>(width), name.c_str(), registry.summary(name).c_str());
  return exit_ok;
}

}  // namespace turtlegas::apps
