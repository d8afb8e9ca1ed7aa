// SPDX-License-Identifier: MIT
#include "turtlegas/world/draw_walker.hpp"

#include "turtlegas/sim/angles.hpp"

namespace turtlegas::world {

void DrawWalker::turn(double degrees) {
  heading = sim::wrap_degrees(heading + degrees);
}

std::optional<sim::WallDef> DrawWalker::move(double distance) {
  const sim::Vec2 d = sim::heading_direction(heading);
  const sim::Vec2 from = pos;
  pos = {pos.x + distance * d.x, pos.y + distance * d.y};
  if (!pen_down || distance == 0.0) return std::nullopt;
  sim::WallDef w;
  w.id = id_ + "-w" + std::to_string(walls_++);
  w.from = from;
  w.to = pos;
  return w;
}

}  // namespace turtlegas::world
