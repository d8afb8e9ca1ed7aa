// SPDX-License-Identifier: MIT
// `turtlegas test WORLD.json...`: runs scripted test worlds headless against their `expect` lists.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

struct TestOptions {
  std::vector<std::string> worlds;
  std::optional<std::string> mode;  ///< "exact" or "step": overrides the worlds' own {"mode": ...}
  double program_budget = 2.0;      ///< wall-clock seconds a program may run without a command
};

/// Adds the `test` subcommand to `app`, parsing into `options`.
CLI::App* add_test_command(CLI::App& app, TestOptions& options);

/// Prints one line per world (PASS or FAIL with what failed) on stdout. Returns 0 when every world
/// passes, 1 when one fails, 2 when one cannot be run (bad file, no `expect`, no `until`).
int test_command(const TestOptions& options, const turtle::Registry& registry);

}  // namespace turtlegas::apps
