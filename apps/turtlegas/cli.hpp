// SPDX-License-Identifier: MIT
// The turtlegas command line as an object: every subcommand's options bound to CLI11, parsed by
// parse() and run by dispatch(). main.cpp is this plus the logger; fuzz/cli_fuzz.cpp feeds fuzzed
// argument vectors to the same parser (docs/fuzzing.md).
#pragma once

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "render_command.hpp"
#include "run_command.hpp"
#include "serve_command.hpp"
#include "sweep_command.hpp"
#include "tag_command.hpp"
#include "test_command.hpp"
#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

/// Which subcommand a parsed command line chose.
enum class Command { run, check, controllers, test, tag, serve, replay, render, sweep };

/// Every subcommand and its options; CLI11 holds references into this object, so it stays where
/// it was made (not copyable or movable).
struct CommandLine {
  CommandLine();
  CommandLine(const CommandLine&) = delete;
  CommandLine& operator=(const CommandLine&) = delete;

  CLI::App app{"turtlegas: a 2-D gas of discs and walls, and turtles with touch sensors (after MIT AI Memo 272)"};
  std::vector<std::string> plugins;
  RunCommandLine run_line;
  std::vector<std::string> check_worlds;
  TestOptions test_opt;
  TagCommandOptions tag_opt;
  ServeCommandOptions serve_opt, replay_opt;
  RenderOptions render_opt;
  SweepOptions sweep_opt;
  CLI::App *check = nullptr, *list = nullptr, *test = nullptr, *tag = nullptr, *serve = nullptr, *replay = nullptr,
           *render = nullptr, *sweep = nullptr;

  /// The subcommand chosen (after a successful parse).
  Command command() const;
};

/// Parses argv into `line`. nullopt: parsed, run dispatch(); otherwise the exit code of a command
/// line that is finished here (--help and --version: 0, printed on `out`; a bad command line: 2,
/// its message on `err`).
std::optional<int> parse(CommandLine& line, int argc, const char* const* argv, std::ostream& out, std::ostream& err);

/// Loads the --plugin libraries into `registry` and runs the chosen command; BadInput is exit code
/// 2 and any other exception 1, each logged as an error.
int dispatch(const CommandLine& line, turtle::Registry& registry);

}  // namespace turtlegas::apps
