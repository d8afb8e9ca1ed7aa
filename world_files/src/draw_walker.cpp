// SPDX-License-Identifier: MIT
#include "turtlegas/world/draw_walker.hpp"

#include <cmath>
#include <numbers>

namespace turtlegas::world {

sim::Vec2 heading_direction(double heading_degrees) {
  double h = std::fmod(heading_degrees, 360.0);
  if (h < 0.0) h += 360.0;
  // Quarter turns are exact: a square room drawn from integer corners closes exactly.
  if (h == 0.0) return {0.0, 1.0};
  if (h == 90.0) return {1.0, 0.0};
  if (h == 180.0) return {0.0, -1.0};
  if (h == 270.0) return {-1.0, 0.0};
  const double r = h * (std::numbers::pi / 180.0);
  return {std::sin(r), std::cos(r)};
}

void DrawWalker::turn(double degrees) {
  heading = std::fmod(heading + degrees, 360.0);
  if (heading < 0.0) heading += 360.0;
}

std::optional<sim::WallDef> DrawWalker::move(double distance) {
  const sim::Vec2 d = heading_direction(heading);
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
