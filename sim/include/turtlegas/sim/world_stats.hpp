// SPDX-License-Identifier: MIT
// What a World counts as it runs (Stats) and the overlap it measures (Overlap): plain data, apart
// from world.hpp so that engine_state.hpp can hold them without including the World.
#pragma once

#include <cstdint>

namespace turtlegas::sim {

/// Counters a run accumulates. Collisions are physical contacts; events also count internal
/// bookkeeping (cell crossings, step boundaries, stale predictions).
struct Stats {
  std::uint64_t ball_ball = 0;
  std::uint64_t ball_wall = 0;
  std::uint64_t ball_wall_end = 0;
  std::uint64_t exits = 0;
  std::uint64_t wedged = 0;   ///< the squeeze rule took a body's velocity (docs/physics.md)
  std::uint64_t crushed = 0;  ///< bodies removed by the squeeze rule
  std::uint64_t folded = 0;   ///< elastic wedges served in closed form (their reflections count as ball_wall*)
  std::uint64_t slides = 0;   ///< sliding flights begun (docs/physics.md, "The sliding flight"; each landing counts as ball_wall)
  /// The energy ledger of the zero-time rules (docs/physics.md, "The energy ledger"): the kinetic
  /// energy each rule took from the balls it acted on (negative: gave), and for `crushed` the
  /// energy (kinetic plus potential) of the balls it removed. Turtles have no energy to count.
  /// World::energy_taken gives it per ball. At e = 1 with no crush every figure is 0 to round-off.
  double energy_wedged = 0.0;
  double energy_crushed = 0.0;
  double energy_folded = 0.0;
  double energy_rules() const { return energy_wedged + energy_crushed + energy_folded; }
  std::uint64_t turtle_wall = 0;
  std::uint64_t turtle_wall_end = 0;
  std::uint64_t turtle_turtle = 0;
  std::uint64_t turtle_ball = 0;
  std::uint64_t cell_crossings = 0;  ///< exact mode
  std::uint64_t stale = 0;           ///< predictions found invalid when their time came
  std::uint64_t steps = 0;           ///< step mode: completed steps
  std::uint64_t events = 0;          ///< everything taken off the event queue
  std::uint64_t collisions() const {
    return ball_ball + ball_wall + ball_wall_end + turtle_wall + turtle_wall_end + turtle_turtle + turtle_ball;
  }
};

/// Overlap found by World::measure_overlap, in world units and as a fraction of the smaller radius.
struct Overlap {
  double depth = 0.0;
  double relative = 0.0;
};

}  // namespace turtlegas::sim
