// SPDX-License-Identifier: MIT
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::formats {

/// What an SVG snapshot draws: the arena, the walls, the live balls and the turtles (with their pen
/// trails) at one time.
struct Snapshot {
  std::string title;
  double time = 0.0;  ///< seconds
  sim::ArenaDef arena;
  std::vector<sim::WallDef> walls;  ///< all walls, the arena's included
  struct Disc {
    sim::Vec2 pos;
    sim::Vec2 vel;
    double radius = 1.0;
  };
  std::vector<Disc> balls;
  /// Balls' paths (ball_trails.hpp), world units: drawn under the balls as thin lines.
  std::vector<std::vector<sim::Vec2>> ball_trails;
  struct Turtle {
    std::string id;
    sim::Vec2 pos;
    double heading = 0.0;  ///< radians, Logo convention (0 is +y, clockwise)
    double radius = 10.0;
    std::vector<sim::Vec2> trail;  ///< pen-down path, world units; empty when nothing was drawn
    bool fault = false;            ///< its program failed (drawn crossed out)
    sim::Layers layers{};          ///< its collision layers (walls it passes through are drawn dashed)
  };
  std::vector<Turtle> turtles;
};

/// The scene as a world file describes it, at t = 0 (with the arena walls of boundary `walls`).
/// Turtles are drawn where they start, without trails.
Snapshot snapshot_of(const sim::WorldDef& def);

/// The live balls of a running world at its current time; def is the scene it was built from
/// (World does not expose its arena). Inline so that code which never draws a running World does
/// not need the engine to link.
inline Snapshot snapshot_of(const sim::World& world, const sim::WorldDef& def) {
  Snapshot s;
  s.title = def.name;
  s.time = world.time();
  s.arena = def.arena;
  s.walls = world.walls();
  s.balls.reserve(world.ball_count());
  for (std::size_t i = 0; i < world.ball_count(); ++i) {
    const sim::BallState b = world.ball(i);
    if (b.alive) s.balls.push_back({b.pos, b.vel, world.radius(i)});
  }
  s.turtles.reserve(world.turtle_count());
  for (std::size_t i = 0; i < world.turtle_count(); ++i) {
    const sim::TurtleState t = world.turtle(i);
    s.turtles.push_back({def.turtles[i].id, t.pos, t.heading, world.turtle_radius(i), {}, false, def.turtles[i].layers});
  }
  return s;
}

/// A world server's world at its current time, with the turtles' pen trails and faults.
Snapshot snapshot_of(const turtle::WorldServer& server, const sim::WorldDef& def);

/// Writes an SVG image of the snapshot: +y up, the arena as a rectangle, walls as lines, balls as
/// circles coloured by speed (with a legend column when there are balls), walls some turtle passes
/// through dashed in blue, pen trails as polylines, turtles as discs with a tick
/// towards their heading and their id beside them, and a title with the name and time. width_px is the
/// size of the arena's longer side in the image.
void write_svg(std::ostream& out, const Snapshot& snapshot, double width_px = 800.0);

}  // namespace turtlegas::formats
