// SPDX-License-Identifier: MIT
// The `expect` list of a 3-D world ("dimensions": 3; docs/worlds.md, "Scripted 3-D worlds"): the
// 2-D kinds that mean something for spheres (event, no_event, count, inside, near, speed, energy,
// max_overlap), positions and speeds of three numbers, and `velocity`, a sphere's velocity at a
// time. Parsed and run here rather than through expect.hpp, whose checks read a 2-D RunView.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "turtlegas/sim/world3d.hpp"
#include "turtlegas/world/world_file_3d.hpp"

namespace turtlegas::world {

struct Assertion3;

/// A 3-D world's `expect` list, parsed. Immutable once read.
struct Expectations3 {
  bool present = false;  ///< the file had an `expect` key
  double until = -1.0;   ///< {"until": T}; < 0 when absent
  double dt = 1.0 / 30;  ///< the file's `dt`: the checks' step (inside, energy, max_overlap)
  std::vector<sim::Mode> modes;  ///< {"mode": "exact"|"step"|"both"}; empty: the caller's choice (exact)
  std::vector<std::shared_ptr<const Assertion3>> entries;
};

struct Expect3Result {
  std::size_t assertions = 0;
  std::vector<std::string> failures;  ///< "expect[2] count ball-wall = 7, wanted >= 10"
};

/// The assertion kinds of a 3-D `expect` list, for messages and docs.
const std::vector<std::string_view>& expect3_kinds();

/// Reads the `expect` list of the 3-D world file `text` (already read into `w`). Throws
/// WorldFileError(file, JSON path, reason), as the loader does.
Expectations3 parse_expect3(std::string_view text, const std::string& file, const World3File& w);

/// Runs `w` to `e.until`, stopping every dt and at every time an entry names, and checks every
/// entry. `on_step` is called at each stop (progress, limits: it may throw to end the run).
Expect3Result run_expect3(const World3File& w, const Expectations3& e,
                          const std::function<void(const sim::World3&)>& on_step = {});

}  // namespace turtlegas::world
