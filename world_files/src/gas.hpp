// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::world::detail {

/// One `gas` entry of a world file, already checked for types and signs.
struct GasSpec {
  std::size_t count = 0;
  double radius = 1.0;  ///< world units, > 0
  double mass = 1.0;
  double charge = 0.0;  ///< every ball's
  double speed = 0.0;   ///< units/s, >= 0: every ball gets exactly this speed
  /// kT in energy units (mass x (units/s)^2, Boltzmann's constant 1), > 0; negative: `speed` instead.
  /// Maxwell-Boltzmann velocities, the gas's total momentum 0 and its kinetic energy exactly
  /// (count - 1) kT (two degrees of freedom per ball less the two of the fixed momentum).
  double temperature = -1.0;
  sim::Vec2 lo, hi;     ///< the region's corners, lo < hi
  std::uint64_t seed = 1;
  std::string id_prefix = "g";
  sim::Layers layers{};  ///< the collision layers every ball of the gas gets
};

/// Area fraction (of the placement rectangle) above which place_gas lays a jittered hexagonal
/// lattice instead of using random sequential addition, which slows sharply towards its jamming
/// limit (about 0.547 in 2-D).
inline constexpr double lattice_fraction = 0.35;

/// The rectangle of allowed centres: inside the region and the arena by one radius. Empty (lo > hi
/// in x or y) when a disc does not fit.
void centre_range(const GasSpec& gas, const sim::ArenaDef& arena, sim::Vec2& lo, sim::Vec2& hi);

/// Appends up to gas.count balls to def.balls, ids id_prefix + 0..count-1 numbered row by row from
/// the bottom: uniformly at random in the region, whole disc inside the region and the arena, not
/// overlapping def's walls, its earlier balls, its turtles or each other; each with speed gas.speed in a
/// uniformly random direction. Deterministic: the same def and spec give bit-identical balls on
/// every platform. Returns the number placed (less than count when the region is too full).
/// With gas.temperature >= 0 the velocities are thermal instead (GasSpec::temperature), from a
/// stream of their own (the positions are those of the same gas at a fixed speed).
/// O(count) expected time.
std::size_t place_gas(sim::WorldDef& def, const GasSpec& gas);

}  // namespace turtlegas::world::detail
