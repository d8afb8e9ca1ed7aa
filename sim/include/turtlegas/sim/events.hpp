// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <string_view>

namespace turtlegas::sim {

/// Kinds of physical event, as they appear in the event log.
enum class EventKind : std::uint8_t {
  ball_ball,      ///< a and b are ball indices
  ball_wall,      ///< a is a ball, b a wall index (contact foot on the segment, ends included)
  ball_wall_end,  ///< a is a ball, b the index of the wall that owns the end point
  exit,           ///< a left the arena (boundary `none`): a ball (b == 0) or a turtle (b == 1)
  turtle_wall,      ///< a is a turtle index, b a wall index
  turtle_wall_end,  ///< a is a turtle, b the index of the wall that owns the end point
  turtle_turtle,    ///< a and b are turtle indices (a is the one whose prediction it was)
  turtle_ball,      ///< a is a turtle, b a ball
  // The squeeze rule (docs/physics.md, "Wedged and crushed bodies"): a is the body, b and c the
  // two obstacles it is held between (walls by wall index, turtles by turtle index; `flags` says
  // which of a, b, c are turtles).
  wedged,   ///< the body's velocity along the squeeze was taken away; it stays in the scene
  crushed,  ///< two obstacles closing on the body left it no room: it is removed
  /// An elastic ball touching two walls (or wall ends) b and c at one instant, reflected by each in
  /// turn until it leaves both, served at once in closed form (docs/physics.md, "The elastic
  /// wedge"); energy kept. Stats::ball_wall / ball_wall_end count each reflection.
  folded,
};

/// Event::flags bits: which of a, b and c index turtles (the squeeze events only), and which of
/// b and c index balls (a ball the squeeze rule holds is an obstacle too); the others are walls.
inline constexpr std::uint8_t kTurtleA = 1, kTurtleB = 2, kTurtleC = 4, kBallB = 8, kBallC = 16;

/// True for the kinds whose `a` is always a turtle.
constexpr bool involves_turtle(EventKind k) { return k >= EventKind::turtle_wall && k <= EventKind::turtle_ball; }

/// The name used in the event log (`ball-ball`, ...).
constexpr std::string_view to_string(EventKind k) {
  switch (k) {
    case EventKind::ball_ball: return "ball-ball";
    case EventKind::ball_wall: return "ball-wall";
    case EventKind::ball_wall_end: return "ball-wall-end";
    case EventKind::exit: return "exit";
    case EventKind::turtle_wall: return "turtle-wall";
    case EventKind::turtle_wall_end: return "turtle-wall-end";
    case EventKind::turtle_turtle: return "turtle-turtle";
    case EventKind::turtle_ball: return "turtle-ball";
    case EventKind::wedged: return "wedged";
    case EventKind::crushed: return "crushed";
    case EventKind::folded: return "folded";
  }
  return "?";
}

/// One logged event. Indices refer to WorldDef::balls, WorldDef::turtles and World::walls().
struct Event {
  double t = 0.0;  ///< seconds
  EventKind kind = EventKind::ball_ball;
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  std::uint32_t c = 0;      ///< the squeeze events' second obstacle (0 otherwise)
  std::uint8_t flags = 0;   ///< the squeeze events: kTurtleA | kTurtleB | kTurtleC | kBallB | kBallC
};

}  // namespace turtlegas::sim
