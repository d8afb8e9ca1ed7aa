// SPDX-License-Identifier: MIT
// The world file's `draw` builders: turtle geometry at load time. A builder walks its commands
// instantly (no time, no physics) and every forward/back stroke with the pen down becomes a wall.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "turtlegas/sim/angles.hpp"
#include "turtlegas/sim/vec2.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::world {

/// A Logo turtle that only draws. Headings in degrees, Logo convention (0 is +y, right turns
/// clockwise). Headings that are multiples of 90 degrees move exactly along the axes, so a builder
/// that starts on integer coordinates lays walls on integer coordinates.
class DrawWalker {
 public:
  DrawWalker(std::string id, sim::Vec2 start, double heading_degrees)
      : pos(start), heading(heading_degrees), id_(std::move(id)) {}

  /// Turns right by `degrees` (negative: left).
  void turn(double degrees);
  /// Moves by `distance` along the heading (negative: backwards). With the pen down and a
  /// non-zero distance, returns the wall from the old position to the new one, with the id
  /// `<builder id>-w<k>`, k = 0, 1, ... counting this builder's walls; layers are left at default.
  std::optional<sim::WallDef> move(double distance);
  /// Walls laid so far.
  std::size_t walls() const { return walls_; }

  sim::Vec2 pos;           ///< world units
  double heading = 0.0;    ///< degrees, Logo convention
  bool pen_down = false;   ///< a builder starts with its pen up

 private:
  std::string id_;
  std::size_t walls_ = 0;
};

/// The unit vector of a Logo heading in degrees, exact at quarter turns (angles.hpp).
using sim::heading_direction;

}  // namespace turtlegas::world
