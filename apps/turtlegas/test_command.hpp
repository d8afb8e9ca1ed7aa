// SPDX-License-Identifier: MIT
// `turtlegas test WORLD.json...`: runs scripted test worlds headless against their `expect` lists,
// each world in a process of its own (a crash or a hang fails that world, by name, and the suite
// goes on), a few at a time (--jobs), with JUnit XML (--junit) and TAP 13 (--tap) for CI.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "run_loop.hpp"
#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

struct TestOptions {
  std::vector<std::string> worlds;
  std::optional<std::string> mode;  ///< "exact" or "step": overrides the worlds' own {"mode": ...}
  double program_budget = 2.0;      ///< wall-clock seconds a program may run without a command
  std::size_t stack_kib = 32;       ///< each turtle program's stack
  std::size_t jobs = 1;             ///< worlds run at once, each in its own process
  double timeout = 0.0;             ///< wall-clock seconds a world may take before it is killed; 0: none
  LimitOptions limits;              ///< --max-wall-seconds, --max-events: each world stops itself cleanly
  std::string junit;                ///< write a JUnit XML report here
  bool tap = false;                 ///< stdout in TAP 13 instead of PASS/FAIL lines
  bool quiet = false;               ///< drop the worlds' log lines (their stderr), keep the results
  bool child = false;               ///< hidden: this process runs worlds[0] alone and reports on fd 3
};

/// Adds the `test` subcommand to `app`, parsing into `options`.
CLI::App* add_test_command(CLI::App& app, TestOptions& options);

/// Prints one line per world (PASS, or FAIL with what failed, or ERROR when it cannot run) on
/// stdout, in the order given, and a count when there are several. Each world runs in a child
/// process (this program again, with `plugins` loaded); its log lines go to stderr before its
/// result unless --quiet. On a terminal, a progress line on stderr says which worlds run, for how
/// long, how far each has got and when it will be done. Returns 0 when every world passes, 1 when
/// one fails (crashes, timeouts and limits included), 2 when one cannot be run (bad file, no
/// `expect`, no `until`) or the options are bad, 130 or 143 when SIGINT or SIGTERM stopped the
/// suite (the worlds running killed, the report written with the rest marked not run).
int test_command(const TestOptions& options, const turtle::Registry& registry, const std::vector<std::string>& plugins);

}  // namespace turtlegas::apps
