// SPDX-License-Identifier: MIT
#include "plugins.hpp"

#include <dlfcn.h>

#include "cli_common.hpp"

namespace turtlegas::apps {

void load_plugins(const std::vector<std::string>& paths, turtle::Registry& registry) {
  using Register = void (*)(turtle::Registry&);
  for (const std::string& path : paths) {
    // A bare name would be searched for on the library path; a plugin is a file the user names.
    const std::string file = path.find('/') == std::string::npos ? "./" + path : path;
    void* handle = ::dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = ::dlerror();
      throw BadInput("--plugin " + path + ": cannot load it: " + (why ? why : "unknown error") +
                     " (is it a plugin built with turtlegas_add_plugin, for this turtlegas?)");
    }
    auto* entry = reinterpret_cast<Register>(::dlsym(handle, "turtlegas_register"));
    if (!entry)
      throw BadInput("--plugin " + path +
                     ": it does not export turtlegas_register; define extern \"C\" void "
                     "turtlegas_register(turtlegas::turtle::Registry&) in it");
    entry(registry);
  }
}

}  // namespace turtlegas::apps
