// SPDX-License-Identifier: MIT
// The statistics file (design.md, "--stats-json"): one JSON object of a run's counts and figures
// (collisions, events, wall_seconds, energy_start, energy_end, max_overlap, and more).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::formats {

/// What a run adds up besides what the World knows (its Stats, walls and cell size).
struct RunFigures {
  std::string world;             ///< the world file, as given
  std::string name;              ///< the scene's name
  sim::Mode mode = sim::Mode::exact;
  double until = 0.0;            ///< seconds: the time asked for
  double t = 0.0;                ///< seconds: the time reached (until, unless the run stopped early)
  /// Empty for a run that reached until; else why it stopped early: "SIGINT", "SIGTERM",
  /// "max-wall-seconds" or "max-events".
  std::string stopped;
  double dt = 0.0;               ///< seconds
  std::uint64_t seed = 0;
  std::size_t balls = 0;         ///< at the start
  std::size_t balls_alive = 0;   ///< at the end
  std::size_t turtles = 0;
  std::size_t turtles_finished = 0;
  std::uint64_t touches = 0;
  std::uint64_t faults = 0;
  double wall_seconds = 0.0;
  /// Of wall_seconds: the overlap self-check's samples (docs/cli.md), which the simulation's
  /// own speed does not include.
  double check_seconds = 0.0;
  double energy_start = 0.0;
  double energy_end = 0.0;
  double max_overlap = 0.0;           ///< world units
  double max_overlap_relative = 0.0;  ///< of the smaller radius
  /// Instants of the run (besides every contact and the end) the overlap was measured at.
  std::uint64_t overlap_samples = 0;
  /// A resumed run (--resume): "state" when it went on from the checkpoint's engine state,
  /// "replay" when it simulated the run again up to the checkpoint; empty otherwise.
  std::string resumed;
  double resumed_t = 0.0;  ///< seconds: the checkpoint's time
  /// Collisions the run had at the checkpoint, when this process took it over from an engine
  /// state without simulating them: not counted in collisions_per_second.
  std::uint64_t collisions_before = 0;
  /// The id of ball i, for the per-body lines of `energy_rules` (absent: "#i", its index).
  std::function<std::string(std::size_t)> ball_name;
  /// Collisions per wall-clock second of simulation: the self-check's time left out, and the
  /// collisions a resumed run took over from its checkpoint's engine state (0 for a run that took
  /// no measurable time).
  double collisions_per_second(const sim::Stats& st) const {
    const double simulating = wall_seconds - check_seconds;
    return simulating > 0.0 ? static_cast<double>(st.collisions() - collisions_before) / simulating : 0.0;
  }
};

/// The energy ledger of the zero-time rules (sim::Stats::energy_wedged...): {"wedged", "crushed",
/// "folded", "total", "bodies_count", "bodies": [{"id", "taken"}...]}, the bodies the rules took
/// most from first (at most 20; bodies_count says how many gave or took anything).
nlohmann::json energy_rules_json(const RunFigures& run, const sim::World& world);

/// The statistics object of a run that ended in `world`.
nlohmann::json stats_json(const RunFigures& run, const sim::World& world);

/// stats_json, indented by two, and a newline.
void write_stats(std::ostream& out, const RunFigures& run, const sim::World& world);

}  // namespace turtlegas::formats
