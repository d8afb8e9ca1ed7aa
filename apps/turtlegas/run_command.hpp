// SPDX-License-Identifier: MIT
// `turtlegas run WORLD.json --until T ...`: simulate a world and write its outputs (design.md,
// "Command line"). A scene with turtles runs through the world server (their programs between
// control steps); one without runs the bare engine.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

struct RunOptions {
  std::string world;
  double until = 0.0;
  std::string mode = "exact";
  std::optional<double> dt;
  std::string events, state_out, stats_json, svg;
  std::string inputs;  ///< an input log to replay (docs/protocol.md, "The input log")
  bool stats = false;
  std::size_t stack_kib = 32;   ///< each turtle program's stack
  double program_budget = 2.0;  ///< wall-clock seconds a program may run without a command
};

/// The `run` subcommand's command line, parsed into a RunOptions by options() once CLI11 has run.
struct RunCommandLine {
  RunOptions parsed;
  double dt = 0.0;
  CLI::Option* dt_option = nullptr;
  RunOptions options() const {
    RunOptions o = parsed;
    if (dt_option && *dt_option) o.dt = dt;
    return o;
  }
};

/// Adds the `run` subcommand to `app`, parsing into `line`; --plugin goes into `plugins`.
CLI::App* add_run_command(CLI::App& app, RunCommandLine& line, std::vector<std::string>& plugins,
                          const char* plugin_help);

/// Runs the world and writes the outputs asked for; exit_ok, or throws BadInput for bad input.
int run_command(const RunOptions& opt, const turtle::Registry& registry);

}  // namespace turtlegas::apps
