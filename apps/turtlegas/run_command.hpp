// SPDX-License-Identifier: MIT
// `turtlegas run WORLD.json --until T ...`: simulate a world and write its outputs (design.md,
// "Command line"). A scene with turtles runs through the world server (their programs between
// control steps); one without runs the bare engine.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "run_loop.hpp"
#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

struct RunOptions {
  std::string world;
  double until = 0.0;
  std::optional<std::string> mode;  ///< exact (the default) or step
  std::optional<double> dt;
  std::string events, state_out, stats_json, svg;
  std::string inputs;  ///< an input log to replay (docs/protocol.md, "The input log")
  bool stats = false;
  std::size_t stack_kib = 32;   ///< each turtle program's stack
  double program_budget = 2.0;  ///< wall-clock seconds a program may run without a command
  /// Limits that end a run early, cleanly, its outputs written up to where it got (exit code 3).
  std::optional<double> max_wall_seconds;
  std::optional<std::uint64_t> max_events;
  /// Checkpoints (checkpoint.hpp): written to `checkpoint` every `checkpoint_every` simulated
  /// seconds, when the run stops early, and at its end; `resume` continues from one.
  std::string checkpoint;
  std::optional<double> checkpoint_every;
  std::string resume;
  /// A recording (docs/recording.md): written to `record`, a keyframe every `keyframe_seconds`
  /// simulated seconds and after every `keyframe_events` engine events (0 turns either off).
  std::string record;
  double keyframe_seconds = 1.0;
  std::uint64_t keyframe_events = 100000;
  std::vector<std::string> plugins;  ///< for the output-is-an-input check
  /// Gas observables (formats/observables.hpp) written to `observe`, with their options.
  std::string observe;
  double observe_from = 0.0, observe_window = 0.0;
  int observe_samples = 20, observe_bins = 20, observe_speed_bins = 40, observe_rdf_bins = 200;
  double observe_rdf_max = 0.0;
  std::string observe_axis = "y";
  double svg_trails = 0.0;  ///< seconds of each ball's path the SVG draws (0: none)
  std::string xyz;          ///< the balls' trajectory as extended XYZ (formats/xyz_trajectory.hpp)
  double xyz_every = 0.0;   ///< simulated seconds between its frames
  /// How many evenly spaced instants --stats measures the deepest overlap at (0: only at
  /// contacts and the end); unset: the default of overlap_samples() in run_command.cpp.
  std::optional<std::uint64_t> overlap_samples;
  /// SIGINT/SIGTERM stop the run cleanly and a fatal signal is reported with the turtle and time
  /// (signals.hpp). False leaves the process's handlers alone: fuzz/cli_fuzz runs under
  /// libFuzzer's and the sanitizers' own.
  bool signal_handlers = true;
};

/// The `run` subcommand's command line, parsed into a RunOptions by options() once CLI11 has run.
struct RunCommandLine {
  RunOptions parsed;
  std::string mode = "exact";
  double dt = 0.0, checkpoint_every = 0.0;
  LimitOptions limits;  ///< --max-wall-seconds, --max-events
  CLI::Option *mode_option = nullptr, *dt_option = nullptr, *checkpoint_every_option = nullptr;
  const std::vector<std::string>* plugins = nullptr;
  RunOptions options() const {
    RunOptions o = parsed;
    if (mode_option && *mode_option) o.mode = mode;
    if (dt_option && *dt_option) o.dt = dt;
    o.max_wall_seconds = limits.wall_seconds();
    o.max_events = limits.events();
    if (checkpoint_every_option && *checkpoint_every_option) o.checkpoint_every = checkpoint_every;
    if (plugins) o.plugins = *plugins;
    return o;
  }
};

/// Adds the `run` subcommand to `app`, parsing into `line`; --plugin goes into `plugins`.
CLI::App* add_run_command(CLI::App& app, RunCommandLine& line, std::vector<std::string>& plugins,
                          const char* plugin_help);

/// Runs the world and writes the outputs asked for: exit_ok, exit_limit, 128 + the signal that
/// stopped it, or throws BadInput for bad input.
int run_command(const RunOptions& opt, const turtle::Registry& registry);

}  // namespace turtlegas::apps
