// SPDX-License-Identifier: MIT
// The one event namer: which body each index of a sim::Event (and of a turtle's contact) names.
// The world server names its log with it, and the event-log writer (formats/) names the bare
// engine's events with it, so both logs say the same thing of the same event.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "turtlegas/sim/events.hpp"

namespace turtlegas::turtle {

/// The ids of an event's bodies: `a`, and `b` unless the kind has no second body (an exit).
struct EventIds {
  std::string_view a;
  std::optional<std::string_view> b;
  std::optional<std::string_view> c;  ///< the squeeze events' second obstacle
};

/// Where the ids come from. `Names` has ball(i), wall(i) and turtle(i), each returning the id of
/// body i (WorldDef::balls / World::walls() / WorldDef::turtles order) as something a
/// std::string_view can be made from; it is a template parameter so that naming a million events
/// costs no indirect call.
template <class Names>
std::string_view other_body(sim::EventKind kind, std::uint32_t index, const Names& names) {
  // A turtle's partner: what a turtle event's b, and a turtle contact's `other`, index.
  switch (kind) {
    case sim::EventKind::turtle_turtle: return names.turtle(index);
    case sim::EventKind::turtle_ball: return names.ball(index);
    default: return names.wall(index);
  }
}

/// The ids of event e (see sim::EventKind for what a and b index).
template <class Names>
EventIds name_event(const sim::Event& e, const Names& names) {
  switch (e.kind) {
    case sim::EventKind::ball_ball: return {names.ball(e.a), names.ball(e.b), std::nullopt};
    case sim::EventKind::ball_wall:
    case sim::EventKind::ball_wall_end: return {names.ball(e.a), names.wall(e.b), std::nullopt};
    // b only says what kind of body left: 1 a turtle, 0 a ball (events.hpp).
    case sim::EventKind::exit: return {e.b == 1 ? names.turtle(e.a) : names.ball(e.a), std::nullopt, std::nullopt};
    // The body, then the two obstacles it was held between (flags: which are turtles).
    case sim::EventKind::wedged:
    case sim::EventKind::crushed: {
      auto body = [&](std::uint32_t i, std::uint8_t turtle, std::uint8_t ball) -> std::string_view {
        if ((e.flags & turtle) != 0) return std::string_view(names.turtle(i));
        return (e.flags & ball) != 0 ? std::string_view(names.ball(i)) : std::string_view(names.wall(i));
      };
      return {(e.flags & sim::kTurtleA) != 0 ? std::string_view(names.turtle(e.a)) : std::string_view(names.ball(e.a)),
              body(e.b, sim::kTurtleB, sim::kBallB), body(e.c, sim::kTurtleC, sim::kBallC)};
    }
    // The ball and the two walls (or the walls owning the ends) it was folded between.
    case sim::EventKind::folded: return {names.ball(e.a), names.wall(e.b), names.wall(e.c)};
    default: return {names.turtle(e.a), other_body(e.kind, e.b, names), std::nullopt};
  }
}

}  // namespace turtlegas::turtle
