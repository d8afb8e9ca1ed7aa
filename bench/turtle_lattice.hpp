// SPDX-License-Identifier: MIT
// The turtle scene of turtle_bench and turtle_soak: a square walled arena with three interior
// bars, turtles of radius 5 on a lattice 30 units apart, headings spread round the compass by the
// golden angle, each running `controller` with {"step": 60, "back_off": 2}.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::bench {

struct TurtleLattice {
  sim::WorldDef def;
  std::vector<turtle::TurtleProgram> programs;
};

inline TurtleLattice turtle_lattice(int turtles, const std::string& name, std::uint64_t seed,
                                    const std::string& controller) {
  const int side = static_cast<int>(std::ceil(std::sqrt(turtles)));
  const double pitch = 30.0, size = side * pitch + 40.0;
  TurtleLattice s;
  sim::WorldDef& def = s.def;
  def.name = name;
  def.seed = seed;
  def.dt = 0.1;
  def.arena.width = def.arena.height = size;
  def.arena.boundary = sim::Boundary::walls;
  for (int k = 1; k < 4; ++k) {
    const int row = k * side / 4;  // a whole row: the bar lies midway between two lattice rows
    const double y = 20.0 + pitch * row;
    def.walls.push_back({"bar" + std::to_string(k), {size * 0.2, y}, {size * 0.8, y}});
  }
  for (int k = 0; k < turtles; ++k) {
    sim::TurtleDef t;
    t.id = "t" + std::to_string(k);
    const int column = k % side, row = k / side;  // filled row by row
    t.pos = {20.0 + pitch * column + pitch / 2, 20.0 + pitch * row + pitch / 2};
    t.heading = std::fmod(k * 2.399963, 2 * M_PI);  // golden-angle spread
    t.radius = 5;
    t.speed = 20;
    t.turn_rate = M_PI;
    def.turtles.push_back(t);
    turtle::TurtleProgram p;
    p.controller = controller;
    p.params = {{"step", 60.0}, {"back_off", 2.0}};
    s.programs.push_back(p);
  }
  return s;
}

}  // namespace turtlegas::bench
