// SPDX-License-Identifier: MIT
// Scenes for the runtime tests: a walled 400 x 400 arena with control steps of 0.1 s, and turtles.
#pragma once

#include <cmath>
#include <string>
#include <utility>

#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::test {

inline sim::WorldDef arena() {
  sim::WorldDef d;
  d.arena.width = 400;
  d.arena.height = 400;
  d.arena.boundary = sim::Boundary::walls;
  d.dt = 0.1;
  return d;
}

/// A turtle of radius 10 at pos with a heading in degrees, turning 180 degrees per second.
inline sim::TurtleDef body(std::string id, sim::Vec2 pos, double heading_deg, double speed = 50) {
  sim::TurtleDef t;
  t.id = std::move(id);
  t.pos = pos;
  t.heading = heading_deg * M_PI / 180.0;
  t.radius = 10;
  t.speed = speed;
  t.turn_rate = M_PI;
  return t;
}

}  // namespace turtlegas::test
