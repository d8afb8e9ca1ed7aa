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
  exit,           ///< a is a ball that left the arena (boundary `none`); b unused
};

/// The name used in the event log (`ball-ball`, ...).
constexpr std::string_view to_string(EventKind k) {
  switch (k) {
    case EventKind::ball_ball: return "ball-ball";
    case EventKind::ball_wall: return "ball-wall";
    case EventKind::ball_wall_end: return "ball-wall-end";
    case EventKind::exit: return "exit";
  }
  return "?";
}

/// One logged event. Indices refer to WorldDef::balls and World::walls().
struct Event {
  double t = 0.0;  ///< seconds
  EventKind kind = EventKind::ball_ball;
  std::uint32_t a = 0;
  std::uint32_t b = 0;
};

}  // namespace turtlegas::sim
