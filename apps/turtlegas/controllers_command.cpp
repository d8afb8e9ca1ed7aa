// SPDX-License-Identifier: MIT
#include "controllers_command.hpp"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "cli_common.hpp"

namespace turtlegas::apps {

int controllers_command(const turtle::Registry& registry) {
  // Each controller on a line with its summary, then its parameters, one a line: name, type and
  // range, default, help.
  std::size_t width = 0;
  for (const std::string& name : registry.names()) width = std::max(width, name.size());
  for (const std::string& name : registry.names()) {
    const turtle::ControllerInfo& info = *registry.info(name);
    std::printf("%-*s  %s%s\n", static_cast<int>(width), name.c_str(), info.summary.c_str(),
                info.restartable ? "" : " [not restartable]");
    if (!info.params_declared) {
      std::printf("    (its params are not declared: they are passed on unchecked)\n");
      continue;
    }
    std::size_t key_width = 0, type_width = 0;
    std::vector<std::string> types;
    for (const turtle::ParamSpec& s : info.params) {
      key_width = std::max(key_width, s.name.size());
      types.push_back(turtle::describe_type(s));
      type_width = std::max(type_width, types.back().size());
    }
    for (std::size_t k = 0; k < info.params.size(); ++k) {
      const turtle::ParamSpec& s = info.params[k];
      const std::string fallback = s.fallback.is_null() ? "-" : s.fallback.dump();
      std::printf("    %-*s  %-*s  default %-8s  %s\n", static_cast<int>(key_width), s.name.c_str(),
                  static_cast<int>(type_width), types[k].c_str(), fallback.c_str(), s.help.c_str());
    }
  }
  return exit_ok;
}

}  // namespace turtlegas::apps
