// SPDX-License-Identifier: MIT
// Scripted test worlds run: a scene against its `expect` list (expect.hpp), in one mode.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/world_server.hpp"
#include "turtlegas/world/scene.hpp"

namespace turtlegas::world {

struct ExpectResult {
  std::size_t assertions = 0;           ///< how many were checked
  std::vector<std::string> failures;    ///< "expect[2] count ball-wall = 7, wanted >= 10"
  bool passed() const { return failures.empty(); }
};

/// What a caller of run_expectations may add to the run (`turtlegas test`: its limits and progress).
struct ExpectHooks {
  /// Called once the server is made, before the first step: bounds on the run (set_event_limit,
  /// set_stop_poll), whose exceptions then come out of run_expectations.
  std::function<void(turtle::WorldServer&)> on_start;
  /// Called after every stop of the run (each control step and sample time); may throw to end the
  /// run, the exception passing through run_expectations.
  std::function<void(const turtle::WorldServer&)> on_step;
};

/// Runs a scene in `mode` through a WorldServer until its {"until": T}, stopping at every control
/// step (and at the times assertions ask for) to feed the checks. A program fault is not an error
/// here: it is a `fault` event (assert {"no_event": "fault"}); a busy loop ends the run as a failure.
/// Throws std::invalid_argument when the server rejects the scene or it has no `until`.
ExpectResult run_expectations(const Scene& scene, const turtle::Registry& registry, sim::Mode mode,
                              turtle::ServerOptions options = {}, const ExpectHooks& hooks = {});

}  // namespace turtlegas::world
