// SPDX-License-Identifier: MIT
// `turtlegas tag`: a blindfold-tag tournament between controllers (docs/controllers.md).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "run_loop.hpp"
#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

struct TagCommandOptions {
  std::string world;
  std::string controllers;  ///< comma-separated
  std::size_t rounds = 20;
  double until = 60.0;
  std::string json_out;
  std::string mode = "exact";
  std::vector<std::string> params;  ///< "controller.key=value", repeatable
  std::size_t stack_kib = 32;       ///< each turtle program's stack
  double program_budget = 2.0;      ///< wall-clock seconds a program may run without a command
  LimitOptions limits;              ///< --max-wall-seconds, --max-events over the whole tournament
};

/// Adds the `tag` subcommand, its options bound to `options`.
CLI::App* add_tag_command(CLI::App& app, TagCommandOptions& options);

/// Plays the tournament, prints the ranking and writes the JSON: exit_ok, or exit_limit or 128 +
/// a signal when it stopped early (the rounds played ranked and written). Throws BadInput for bad
/// input.
int run_tag_command(const TagCommandOptions& options, const turtle::Registry& registry);

}  // namespace turtlegas::apps
