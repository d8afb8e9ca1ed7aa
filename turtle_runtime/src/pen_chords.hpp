// SPDX-License-Identifier: MIT
// What a lowered pen lays along an arc (Turtle::arc, drive, wheels): the arc's chords, a polyline
// the line pen adds to the trail and the wall pen lays as walls, one per chord.
#pragma once

#include <vector>

#include "turtlegas/sim/vec2.hpp"

namespace turtlegas::turtle::detail {

/// The most a chord may depart from its arc (its sagitta), as a fraction of the turtle's radius:
/// a body that fits between the chords and the arc is smaller than a twentieth of the turtle.
inline constexpr double chord_sagitta = 1.0 / 20.0;
/// The most of the turn one chord spans, radians (45 degrees: a small circle still has 8 sides).
inline constexpr double chord_turn = 0.7853981633974483;

/// The turn the chords of an arc that turned `turned` radians draw: all of it up to a lap, else a
/// lap and then what is left past the last whole lap (same sign as `turned`).
double drawn_turn(double turned);

/// The chords of an arc that began at `start` with heading `heading` (radians, Logo convention)
/// and drove at `speed` units/s (negative: backwards) turning at `rate` rad/s (positive
/// clockwise) through `turned` radians (rate times the time driven): the polyline's vertices after
/// `start`, equally spaced in angle, the last of them `end` (where the turtle stopped, exactly).
/// Each chord spans at most chord_turn of the turn and has a sagitta of at most chord_sagitta *
/// `radius`. An arc of more than a lap is drawn as its circle once and then the rest: at most two
/// laps of vertices. A straight stroke (rate 0) or a turn on the spot (speed 0) is just `end`.
std::vector<sim::Vec2> arc_chords(sim::Vec2 start, double heading, double speed, double rate, double turned,
                                  sim::Vec2 end, double radius);

}  // namespace turtlegas::turtle::detail
