// SPDX-License-Identifier: MIT
// Balls' trails for the SVG snapshot (`turtlegas run --svg F --svg-trails S`): each ball's path over
// the last S seconds, drawn along its flight, not as chords. From its state at the start and the
// impulse of every collision after (World::set_impulse_log), the path is the closed-form flight
// (sim/field_flight.hpp: a line, a parabola, a circle or a trochoid) between collisions, sampled
// densely enough to look smooth (48 points a turn, 8 more on a parabola).
#pragma once

#include <cstddef>
#include <vector>

#include "turtlegas/sim/field_flight.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::formats {

class BallTrails {
 public:
  /// Trails from time `from` on of the first `max_balls` balls of a world built from `def` (its
  /// fields and each ball's charge and mass; call before the World takes def's balls).
  BallTrails(const sim::WorldDef& def, double from, std::size_t max_balls = 1000);

  double from() const { return from_; }
  bool started() const { return started_; }
  /// The world has reached from(): every traced ball's state is taken.
  void start(const sim::World& world);
  /// Collisions after start(), in the order the engine reported them (earlier ones are ignored).
  void take(const std::vector<sim::Impulse>& batch);
  /// Flies every trail on to the world's current time, ending it where the world has the ball.
  void finish(const sim::World& world);
  /// How far the flown trails ended from where the world had the balls at finish() (world units;
  /// round-off, unless something moved a ball without an impulse: the squeeze rule, an exit).
  double end_mismatch() const { return end_mismatch_; }
  /// The paths, in world units; a periodic arena's wrap-around starts a new piece.
  std::vector<std::vector<sim::Vec2>> polylines() const;

 private:
  struct Track {
    sim::Vec2 x, v;
    double t = 0.0;
    bool alive = true;
    std::vector<sim::Vec2> points;
  };
  void fly(std::size_t i, double t);

  double from_;
  bool started_ = false;
  bool periodic_;
  double width_, height_;
  std::vector<double> mass_;
  std::vector<sim::FieldFlight> field_;  ///< per ball: a and w (v unused)
  std::vector<Track> tracks_;
  double end_mismatch_ = 0.0;
};

}  // namespace turtlegas::formats
