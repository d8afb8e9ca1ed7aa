// SPDX-License-Identifier: MIT
// What the turtlegas commands share: exit codes, the bad-input error, loading a world file, building
// the World or the world server for it, and the words and numbers of their summaries.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/world_server.hpp"
#include "turtlegas/world/scene.hpp"

namespace turtlegas::apps {

// design.md, "Command line": 0 success, 2 bad input (world file or arguments), 1 anything else.
constexpr int exit_ok = 0;
constexpr int exit_failure = 1;
constexpr int exit_bad_input = 2;

/// A problem with the command line or the world file: exit code 2.
struct BadInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The scene of a world file; a bad file is BadInput.
world::Scene load(const std::string& file, const turtle::Registry& registry);
/// As load, and the file's bytes, read once: what a command loads is what it records and hashes,
/// even when the file is edited while it runs.
world::Scene load(const std::string& file, const turtle::Registry& registry, std::string& bytes);


/// As make_world, for a scene with turtles: the server also checks controllers and sensors.
std::unique_ptr<turtle::WorldServer> make_server(const world::Scene& scene, const turtle::Registry& registry,
                                                 const turtle::ServerOptions& options, const std::string& file);

/// The engine rejects a scene it cannot run (a cell size against the memo's rule, say) with
/// std::invalid_argument: that is the world file's fault, so exit code 2.
template <class Def>  // const sim::WorldDef& or sim::WorldDef&&
sim::World make_world(Def&& def, sim::Mode mode, const std::string& file) {
  try {
    return sim::World(std::forward<Def>(def), mode);
  } catch (const std::invalid_argument& e) {
    throw BadInput(file + ": " + std::string(sim::to_string(mode)) + " mode: " + e.what());
  }
}

/// Range checks for numeric options, for every command: applied to the option's text before CLI11
/// converts it, which would read "-1" into a std::size_t as 2^64 - 1 and take "nan" and "inf" as
/// numbers. A value out of range is a parse error (exit code 2): "--rounds: must be a whole
/// number from 1 to 1000000 (got -1)".
///
/// A finite number from `min` to `max` (> min when min_exclusive), of `unit` ("seconds"; may
/// be empty): `run->add_option("--dt", dt)->check(real_in(0, 1e9, "seconds", true))`.
CLI::Validator real_in(double min, double max, const std::string& unit, bool min_exclusive = false);
/// A whole number from `min` to `max`, written without a fraction or exponent.
CLI::Validator integer_in(std::int64_t min, std::int64_t max, const std::string& unit = {});

/// The options of every command that runs turtle programs (run, test, tag, sweep), one
/// definition with one range: `--stack-kib` (16 KiB to 1 GiB; below 16 KiB the API's own frames
/// do not fit) and `--program-budget` (seconds of wall clock, > 0 and at most 10^6).
CLI::Option* add_stack_kib_option(CLI::App& cmd, std::size_t& kib);
CLI::Option* add_program_budget_option(CLI::App& cmd, double& seconds, const std::string& what_stops);

/// "3 balls, 1 wall (+4 arena walls), 2 turtles".
std::string count_summary(const sim::WorldDef& def, std::size_t balls);
/// Six significant digits, for summaries.
std::string fmt(double v);
/// "wander x3, script": each controller the scene uses and how many turtles run it, in file order.
std::string controller_summary(const world::Scene& scene);

/// Whether the file opens as a recording's header does: {"format": "turtlegas-recording/...,
/// with any JSON whitespace between the tokens. Reads at most 256 bytes.
bool is_recording(const std::string& path);

}  // namespace turtlegas::apps
