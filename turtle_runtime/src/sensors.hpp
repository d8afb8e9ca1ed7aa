// SPDX-License-Identifier: MIT
// Touch sensors: which arcs a contact's bearing fires, and the one Touch builder, used for the
// interrupts of each control step (WorldServer::Impl::control_step) and for Turtle::touching().
// Inline: the builder runs for every contact of every step.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "turtlegas/sim/angles.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::turtle::detail {

/// Bit k set when arc k holds `bearing` (degrees clockwise from the heading).
inline std::uint64_t sensors_for(const std::vector<SensorArc>& arcs, double bearing) {
  std::uint64_t fired = 0;
  for (std::size_t k = 0; k < arcs.size(); ++k) {
    const SensorArc& s = arcs[k];
    const double span = s.to - s.from;
    if (sim::wrap_degrees(bearing - s.from) < (span >= 360.0 ? 360.0 : sim::wrap_degrees(span))) fired |= std::uint64_t{1} << k;
  }
  return fired;
}

/// Touch::kind for a contact's kind.
inline std::string kind_word(sim::EventKind k) {
  switch (k) {
    case sim::EventKind::turtle_wall: return "wall";
    case sim::EventKind::turtle_wall_end: return "wall-end";
    case sim::EventKind::turtle_turtle: return "turtle";
    case sim::EventKind::turtle_ball: return "ball";
    default: return "?";
  }
}

/// Contact c as the turtle's program sees it: bearing and sensors for heading `heading_degrees`
/// (the API's degrees, not wrapped), the sensors' names, what was touched (`what`, its id).
inline Touch make_touch(const sim::TurtleContact& c, double heading_degrees, const std::vector<SensorArc>& arcs,
                        const std::vector<std::string>& sensor_names, std::string_view what) {
  // The contact point lies against the normal (which points from the obstacle to the turtle).
  const sim::Vec2 d = -c.normal;
  Touch t;
  t.bearing = sim::wrap_degrees(sim::to_degrees(sim::heading_of(d)) - heading_degrees);
  t.sensors = sensors_for(arcs, t.bearing);
  t.sensor_names = &sensor_names;
  t.what = std::string(what);
  t.kind = kind_word(c.kind);
  t.t = c.t;
  return t;
}

}  // namespace turtlegas::turtle::detail
