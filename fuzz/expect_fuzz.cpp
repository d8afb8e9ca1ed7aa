// SPDX-License-Identifier: MIT
// libFuzzer harness for scripted test worlds and games: the input is a world file whose `expect`
// list and `game` block are what the fuzzer varies (seeds: worlds/tests/ and worlds/tag.json).
// A scene that loads runs its expect list (as `turtlegas test` does) when it is short enough, and
// otherwise a bounded run; expectations failing is a normal answer, a crash or hang is a finding.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_common.hpp"
#include "turtlegas/world/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace turtlegas;
  const std::optional<world::Scene> loaded = fuzz::load_scene(data, size);
  if (!loaded) return 0;
  const world::Scene& scene = *loaded;
  const auto& until = scene.expect.until;
  const bool short_run = until && *until <= fuzz::max_time && *until / scene.def.dt <= fuzz::max_steps;
  try {
    if (short_run) {
      turtle::ServerOptions options;
      options.program_budget = 1.0;
      std::vector<sim::Mode> modes = scene.expect.modes;
      if (modes.empty()) modes = {sim::Mode::exact, sim::Mode::step};
      for (sim::Mode mode : modes) (void)world::run_expectations(scene, fuzz::registry(), mode, options);
    } else {
      fuzz::bounded_run(scene, sim::Mode::exact);
    }
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
