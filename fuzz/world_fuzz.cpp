// SPDX-License-Identifier: MIT
// libFuzzer harness: a world file's bytes through the loader and, when it loads, a bounded run in
// both modes (fuzz_common.hpp). A loader error (WorldFileError) is the expected answer to most
// inputs; anything else that escapes, a sanitizer report, a hang (libFuzzer's -timeout) or a
// NaN position is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace turtlegas;
  const std::optional<world::Scene> scene = fuzz::load_scene(data, size);
  if (!scene) return 0;
  for (sim::Mode mode : {sim::Mode::exact, sim::Mode::step}) {
    try {
      fuzz::bounded_run(*scene, mode);
    } catch (const std::invalid_argument&) {
      // A scene the engine refuses to build in this mode (validate's message): not a finding.
    }
  }
  return 0;
}
