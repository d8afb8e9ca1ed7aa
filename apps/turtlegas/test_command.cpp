// SPDX-License-Identifier: MIT
#include "test_command.hpp"

#include <chrono>
#include <cstdio>
#include <stdexcept>

#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/world/expect.hpp"
#include "turtlegas/world/scenario.hpp"
#include "turtlegas/world/world_file.hpp"

namespace turtlegas::apps {
namespace {

namespace tw = turtlegas::world;
using Clock = std::chrono::steady_clock;

const char* mode_name(sim::Mode m) { return sim::to_string(m).data(); }

/// 0 pass, 1 fail, 2 bad input; prints the world's line.
int test_one(const std::string& file, const TestOptions& options, const turtle::Registry& registry) {
  tw::Scene scene;
  try {
    scene = tw::load_scene(file, registry);
  } catch (const tw::WorldFileError& e) {
    std::printf("ERROR %s\n", e.what());
    return 2;
  }
  const tw::Expectations& expect = scene.expect;
  if (!expect.present) {
    std::printf("ERROR %s: no \"expect\" list; a test world needs one, e.g. \"expect\": [{\"until\": 10}, ...]\n",
                file.c_str());
    return 2;
  }
  if (!expect.until) {
    std::printf("ERROR %s: /expect: no {\"until\": T}; add one to say how long the test runs\n", file.c_str());
    return 2;
  }
  std::vector<sim::Mode> modes = expect.modes;
  if (options.mode) modes = {sim::mode_from_string(*options.mode).value_or(sim::Mode::exact)};  // CLI11 checked it
  if (modes.empty()) modes = {sim::Mode::exact};

  turtle::ServerOptions server_options;
  server_options.program_budget = options.program_budget;
  const auto start = Clock::now();
  std::string failures;
  std::size_t assertions = 0;
  for (sim::Mode mode : modes) {
    tw::ExpectResult r;
    try {
      r = tw::run_expectations(scene, registry, mode, server_options);
    } catch (const std::invalid_argument& e) {
      std::printf("ERROR %s: %s mode: %s\n", file.c_str(), mode_name(mode), e.what());
      return 2;
    }
    assertions += r.assertions;
    for (const std::string& f : r.failures) {
      failures += failures.empty() ? "" : "; ";
      if (modes.size() > 1) failures += std::string(mode_name(mode)) + " mode: ";
      failures += f;
    }
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (!failures.empty()) {
    std::printf("FAIL %s: %s\n", file.c_str(), failures.c_str());
    return 1;
  }
  std::string how;
  if (modes.size() > 1) how = "exact and step, ";
  std::printf("PASS %s (%s%zu assertion%s, %.2f s)\n", file.c_str(), how.c_str(), assertions,
              assertions == 1 ? "" : "s", seconds);
  return 0;
}

}  // namespace

CLI::App* add_test_command(CLI::App& app, TestOptions& options) {
  CLI::App* cmd = app.add_subcommand(
      "test", "Run scripted test worlds headless against their \"expect\" lists; one line per world, exit 1 on a failure");
  cmd->add_option("worlds", options.worlds, "World files with an \"expect\" list")->required();
  cmd->add_option("--mode", options.mode, "exact or step: overrides each world's own {\"mode\": ...}")
      ->check(CLI::IsMember(sim::mode_names));
  cmd->add_option("--program-budget", options.program_budget,
                  "Wall-clock seconds a turtle program may run without issuing a command before the run stops")
      ->capture_default_str();
  return cmd;
}

int test_command(const TestOptions& options, const turtle::Registry& registry) {
  int worst = 0;
  std::size_t passed = 0, failed = 0, bad = 0;
  for (const std::string& file : options.worlds) {
    const int rc = test_one(file, options, registry);
    std::fflush(stdout);
    (rc == 0 ? passed : rc == 1 ? failed : bad) += 1;
    // Bad input outranks a failure: a world that cannot run is a broken test, not a result.
    if (rc == 2 || (rc == 1 && worst == 0)) worst = rc;
  }
  if (options.worlds.size() > 1)
    std::printf("%zu passed, %zu failed, %zu could not run\n", passed, failed, bad);
  return worst;
}

}  // namespace turtlegas::apps
