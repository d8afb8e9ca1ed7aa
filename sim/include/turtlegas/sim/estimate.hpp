// SPDX-License-Identifier: MIT
// What a run of a scene will cost, from its scales alone (no engine is built): the one model
// behind `check`'s warnings ("this scene predicts 1e15 events"), the warnings of `run`, `render`
// and `tag`, the size of a run's first chunk, and anyone sizing a run. The wording of the
// warnings is the app's (apps/turtlegas/scene_scales.hpp); the numbers are here.
#pragma once

#include <cstddef>
#include <optional>

#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim {

/// No body: no ball or turtle moves, or none is charged in a magnetic field.
inline constexpr std::size_t kNoBody = static_cast<std::size_t>(-1);

/// What dominates a run's events per simulated second (WorkEstimate::events_per_s).
enum class WorkCause {
  none,      ///< no cell is known yet, or no body moves
  speed,     ///< the fastest body crossing cells at its own speed
  fields,    ///< the fastest ball crossing cells at a speed the fields give it across the arena
  gyration,  ///< a charged ball's magnetic circle, re-planned every 8 turns (exact mode)
};

/// Orders of magnitude, per simulated second and for a run to `until`. Every figure is finite
/// (a scale that overflows gives the largest double) and >= 0. Each is an upper estimate of the
/// steady rate, meant to tell 1e6 from 1e15 (a speed of 1e150, a dt of 1e-300), not to time
/// ordinary runs.
struct WorkEstimate {
  /// Each body's speed bound: a ball's speed plus what the fields can give it while it crosses
  /// the arena, sqrt(2 a L) (a = |g| + |q| |E| / m, L the arena's larger side: energy bounds
  /// it); a turtle's speed plus its turn rate times its radius.
  double max_speed = 0.0;         ///< units/s: the largest speed bound
  std::size_t fastest = kNoBody;  ///< whose: def.balls[i], or def.turtles[i - def.balls.size()]
  bool by_fields = false;         ///< the fields give that ball most of its speed bound
  double speed_sum = 0.0;         ///< units/s: twice each ball's speed bound, plus each turtle's

  /// Exact mode's re-plans of charged balls gyrating in the magnetic field: a circle is
  /// re-planned at most every 8 turns (docs/physics.md, "Horizons"), |q Bz / m| / (16 pi) a
  /// second for each. 0 in step mode and without a magnetic field.
  double replans_per_s = 0.0;
  double turns_per_s = 0.0;         ///< the most frequent gyration's turns per second
  std::size_t gyrating = kNoBody;   ///< that ball's index in def.balls

  /// Steps per second: step mode's, and the turtles' control steps (1 / dt for each; both at
  /// once are still 1 / dt).
  double steps_per_s = 0.0;

  /// Balls with walls and with each other: a dilute-gas rate, 2 sigma n v per ball (sigma the
  /// contact distance, n the number density; half of it per pair), walls met at v / L (L the
  /// arena's smaller side), v each ball's speed bound.
  double collisions_per_s = 0.0;

  double cell = 0.0;  ///< the cell side the crossings are counted for
  /// Cells crossed: speed_sum / cell (exact mode's crossing events; step mode re-files the
  /// bodies as often). Twice a ball's speed bound covers the crossings and the collisions of a
  /// gas at the engine's 0.3 balls per cell.
  double crossings_per_s = 0.0;
  /// What the warnings and the pacing count: crossings_per_s + replans_per_s. The collision
  /// term is left out: the doubled speeds already cover a gas's collisions, and a dilute-gas
  /// rate is wrong by orders of magnitude for a pile at rest (its n is huge, its v zero).
  double events_per_s = 0.0;
  WorkCause cause = WorkCause::none;  ///< what dominates events_per_s

  Mode mode = Mode::exact;  ///< the mode estimated
  double until = 0.0;       ///< the run's end, s
  /// The mode's events for the whole run to `until`: exact mode's collisions, crossings and
  /// re-plans, or step mode's steps and collisions.
  double events = 0.0;

  /// Counts the crossings, events_per_s, its cause and `events` for cells of side `cell` (the
  /// World's cell_size(), known once it is built); a `cell` that is not > 0 changes nothing.
  void set_cell(double cell);
};

/// The estimate for `def` run in `mode` to time `until`, for cells of side `cell`, or when it is
/// not given the cell `World` would choose (detail::choose_cell_size; two radii if that throws).
/// Kinetic theory, not a simulation (see docs/physics.md, "What a run costs"): expect it within a
/// factor of a few of the truth for gases.
WorkEstimate estimate_work(const WorldDef& def, Mode mode, double until, std::optional<double> cell = {});

}  // namespace turtlegas::sim
