// SPDX-License-Identifier: MIT
// libFuzzer harness for scripted test worlds and games: the input is a world file whose `expect`
// list and `game` block are what the fuzzer varies (seeds: worlds/tests/ and worlds/tag.json).
// A scene that loads runs its expect list (as `turtlegas test` does) when it is short enough, and
// otherwise a bounded run; expectations failing is a normal answer, a crash or hang is a finding.
//
// Protocol messages of the network server get a harness of the same shape when the server lands:
// fuzz/CMakeLists.txt has the hook (turtlegas_add_fuzzer).
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "fuzz_common.hpp"
#include "turtlegas/world/scenario.hpp"
#include "turtlegas/world/world_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace turtlegas;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  world::Scene scene;
  try {
    scene = world::parse_scene(text, "fuzz.json", fuzz::registry());
  } catch (const world::WorldFileError&) {
    return 0;
  }
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
