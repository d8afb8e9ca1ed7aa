// SPDX-License-Identifier: MIT
// The walls: every wall of the scene (the arena's four too, last) as the segments the times of
// impact use, their ends as collision objects (one per distinct point of the fixed walls), their
// collision layers, and the walls added while the world runs.
#pragma once

#include <cstdint>
#include <vector>

#include "../cell_grid.hpp"
#include "arena.hpp"
#include "records.hpp"
#include "turtlegas/sim/toi.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim::detail {

class Walls {
 public:
  Walls() = default;
  /// The scene's walls, then the arena's (Boundary::walls). `with_layers`: keep the collision
  /// layers of walls and ends (scenes with extras).
  Walls(const WorldDef& def, bool with_layers);

  std::vector<WallDef> defs;
  std::vector<Segment> segments;       ///< per wall; a moving wall's as of its last keyframe
  std::vector<WallEnd> ends;           ///< the fixed walls' ends
  std::vector<std::uint32_t> mover_of;  ///< per wall: its index among the moving walls, or kNone
  std::vector<Layers> layers;          ///< per wall (with_layers only); visibility clears a mask
  std::vector<Layers> end_layers;      ///< per end: its walls' categories and masks together

  /// Which walls move (the table leaves them out: CellGrid's `skip`).
  std::vector<bool> moving() const;
  /// Rebuilds the ends' layers from the fixed walls' layers (after a change of visibility).
  void rebuild_end_layers();

  /// Checks a wall to be added while the world runs, before the bodies are checked against it;
  /// throws std::invalid_argument saying what is wrong.
  void check_new(const WallDef& wall, const ArenaDef& arena) const;
  /// Appends a checked wall: indices of walls and ends named by predictions stay valid. Returns
  /// its index.
  std::uint32_t add(const WallDef& wall, bool with_layers);

 private:
  void add_end_layers(Vec2 p, const Layers& l);
};

}  // namespace turtlegas::sim::detail
