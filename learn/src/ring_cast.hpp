// SPDX-License-Identifier: MIT
// All the rays of one turtle's sensors at once. sim::World::cast_ray walks the grid anew for each
// ray (about 270 ns a ray in worlds/learn/swarm16.json, most of a VecWorld step); the rays of a ring
// share their origin, so the bodies and walls within reach of it are gathered once and each ray
// tests only those, with the engine's own closed forms (sim/ray_cast.hpp: ray_disc, ray_segment,
// ray_point), the same range test and the same tie rule (lower target, then lower index). The
// answers are cast_ray's, bit for bit (ring_cast_test checks them on random scenes), in scenes the
// caster applies to: still walls that are always there, an arena that is not periodic, and few
// enough walls that a pass over them per turtle is cheap. Elsewhere VecWorld calls cast_ray.
#pragma once

#include <cstdint>
#include <vector>

#include "turtlegas/sim/ray_cast.hpp"
#include "turtlegas/sim/world.hpp"

namespace turtlegas::learn::detail {

class RingCaster {
 public:
  /// Whether the caster gives cast_ray's answers for this world: none of its walls moves or comes
  /// and goes, the arena is not periodic, and it has at most `max_walls` walls.
  static bool applies(const sim::World& world, const sim::WorldDef& def, std::size_t max_walls = 64);
  /// The walls of `world` (the scene's and the arena's), the layers of def's balls and turtles.
  RingCaster(const sim::World& world, const sim::WorldDef& def);

  /// Turtle positions of `world` now, read once for all the rings cast before the next call.
  void begin(const sim::World& world);
  /// The first hit of each ray from turtle `self` at `origin` with `layers`: dirs[k] is ray k's
  /// direction (non-zero, finite), ranges[k] its range; reach >= every range. out[k] = cast_ray's.
  void cast(const sim::World& world, sim::Vec2 origin, const sim::Layers& layers, std::uint32_t self,
            const std::vector<sim::Vec2>& dirs, const std::vector<double>& ranges, double reach,
            std::vector<sim::RayHit>& out);

 private:
  struct Disc {
    sim::Vec2 pos;
    double r;
    sim::RayTarget target;
    std::uint32_t index;
  };
  struct End {
    sim::Vec2 p;
    std::uint32_t wall;  // the first wall that ends there
    sim::Layers layers;  // there for a body if any wall that ends there is
  };
  std::vector<sim::Segment> segments_;
  std::vector<sim::Layers> wall_layers_;
  std::vector<End> ends_;
  std::vector<sim::Layers> ball_layers_, turtle_layers_;
  std::vector<sim::Vec2> turtle_pos_;
  std::vector<double> turtle_r_;
  std::vector<std::uint8_t> turtle_alive_;
  double max_ball_r_ = 0.0;
  // Scratch of one cast: the candidates within reach.
  std::vector<Disc> discs_;
  std::vector<std::uint32_t> walls_, near_ends_;
  std::vector<std::uint32_t> balls_;
};

}  // namespace turtlegas::learn::detail
