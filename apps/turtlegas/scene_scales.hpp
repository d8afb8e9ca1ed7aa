// SPDX-License-Identifier: MIT
// What a scene's scales predict (sim::estimate_work, the one cost model), in words: for `check`'s
// warnings about runs that would never finish, `run`'s, `render`'s and `tag`'s, and for the size of
// a run's first chunk (so that a runaway scene still shows progress and obeys its limits).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "turtlegas/sim/estimate.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::apps {

/// sim::estimate_work's figures for a scene, in words. Order-of-magnitude predictions, meant to
/// catch absurd scenes (a speed of 1e150, a dt of 1e-300), not to time ordinary ones.
struct SceneScales {
  /// Events per simulated second (WorkEstimate::events_per_s: cell crossings and magnetic
  /// re-plans), 0 until set_cell() gives the cell.
  double events_per_second = 0.0;
  std::string events_why;  ///< the body that dominates, in numbers
  /// Steps per simulated second: step mode's steps, and the turtles' control steps (1/dt each).
  double steps_per_second = 0.0;
  std::string steps_why;

  sim::WorkEstimate work;  ///< the numbers
  std::string fastest_id;    ///< the id of work.fastest (the World may take the balls before set_cell)
  std::string gyrating_id;   ///< the id of work.gyrating
  /// The event rate and its cause for cells of this side (the engine's cell_size()).
  void set_cell(double cell);
};

/// The scene's speeds and steps; events_per_second needs set_cell() (a world's cell size is known
/// once it is built; the World may take the scene's balls then).
SceneScales predict_scales(const sim::WorldDef& def, sim::Mode mode);

/// A run of `seconds` predicting more than this many events, or steps, is warned about.
constexpr double absurd_events = 1e10;
constexpr double absurd_steps = 1e9;
/// What the warnings convert counts into wall time with: a fast run's pace.
constexpr double nominal_events_per_second = 1e7;

/// One line per absurd prediction for a run of `seconds` (simulated), naming its cause and the
/// wall time it would take at the nominal pace; `span` says what the run is ("a run to
/// --until 1e308", "the expect list's run to until 1e12", "one simulated second").
std::vector<std::string> scale_warnings(const SceneScales& scales, double seconds, const std::string& span);

/// The coordinate-to-radius ratio above which contacts may overlap by more than the engine's 1e-9
/// of a radius: positions carry round-off of a few eps of the coordinates (docs/physics.md, "the
/// overlap bound"), measured at 1.5e-10 r at a ratio of 1e6 and 2.6e-9 r at 1e7.
constexpr double precise_coordinate_ratio = 1e6;

/// A warning when the scene's largest coordinate (arena, walls, bodies) exceeds
/// precise_coordinate_ratio times its smallest body radius, naming both and the overlap to expect;
/// nothing otherwise.
std::optional<std::string> precision_warning(const sim::WorldDef& def);

/// "12 s", "3.5 min", "2.1 h", "4.2 days", "3e+134 years".
std::string human_duration(double seconds);

}  // namespace turtlegas::apps
