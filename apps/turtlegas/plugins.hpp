// SPDX-License-Identifier: MIT
// Controller plugins (`--plugin`, TURTLEGAS_PLUGIN_PATH, a world file's "plugins"): shared modules
// that add controllers to the registry.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

/// Loads controller plugins: shared modules exporting `extern "C" void turtlegas_register(Registry&)`,
/// built against the same turtlegas headers and compiler (see docs/controllers.md). They stay loaded
/// for the life of the program, since the registry holds their code. BadInput (naming the file and
/// `given_by`, e.g. "TURTLEGAS_PLUGIN_PATH", when not empty) for a file that is not such a plugin:
/// not a regular file (a FIFO is refused, never opened for reading), not a 64-bit shared library
/// of this machine, cut short (a loadable segment past the file's end, which dlopen would map and
/// crash on), without turtlegas_register, whose registration throws, or that registers a name
/// already taken (a built-in controller, `remote`, or another plugin's).
void load_plugins(const std::vector<std::string>& paths, turtle::Registry& registry, const std::string& given_by = {});

/// The plugins a TURTLEGAS_PLUGIN_PATH value names: colon-separated entries, each a plugin file or
/// a directory whose `*.so` files are all loaded (in name order). Empty entries are skipped.
std::vector<std::string> plugin_path_entries(const char* value);

/// The plugin file (its absolute path) that registered `controller`; none for a built-in.
std::optional<std::string> plugin_of(const std::string& controller);

/// For a recording's header (formats::RecordingHeader::plugins): the plugins whose controllers
/// `controllers` names, [{"file": ABSOLUTE_PATH, "controllers": [NAME, ...]}, ...].
nlohmann::ordered_json plugins_used(const std::vector<std::string>& controllers);

/// The plugins `input` names, loaded: a world file's "plugins" (paths relative to the world file;
/// docs/worlds.md), or a recording's (formats::RecordingHeader::plugins) whose controllers are not
/// registered already. BadInput naming the input for a plugin that is missing or bad (a
/// recording's: which plugin, which controllers, and how to give it). Anything else about the
/// input is left to the command that reads it.
void load_input_plugins(const std::string& input, turtle::Registry& registry);
/// load_input_plugins for the world a sweep spec names ("world", relative to the spec).
void load_sweep_plugins(const std::string& spec, turtle::Registry& registry);

}  // namespace turtlegas::apps
