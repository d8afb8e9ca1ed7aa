// SPDX-License-Identifier: MIT
#include "turtlegas/formats/state_file.hpp"

#include <cstddef>
#include <string>

#include "turtlegas/formats/json_text.hpp"
#include "turtlegas/sim/angles.hpp"

namespace turtlegas::formats {

void write_state(std::ostream& out, const sim::World& world, const RunNames& names) {
  std::string buf = "{\"t\": ";
  append_number(buf, world.time());
  buf += ", \"balls\": [";
  bool first = true;
  for (std::size_t i = 0; i < world.ball_count(); ++i) {
    const sim::BallState b = world.ball(i);
    if (!b.alive) continue;
    buf += first ? "\n  " : ",\n  ";
    first = false;
    buf += "{\"id\": ";
    append_json_string(buf, names.ball(i));
    buf += ", \"pos\": [";
    append_number(buf, b.pos.x);
    buf += ", ";
    append_number(buf, b.pos.y);
    buf += "], \"vel\": [";
    append_number(buf, b.vel.x);
    buf += ", ";
    append_number(buf, b.vel.y);
    buf += "]}";
    if (buf.size() > (1u << 20)) {
      out << buf;
      buf.clear();
    }
  }
  buf += first ? "], \"turtles\": [" : "\n], \"turtles\": [";
  // A turtle that has left the world (crushed, out of an open arena, removed) is not in it, as an
  // exited ball is not.
  first = true;
  for (std::size_t i = 0; i < world.turtle_count(); ++i) {
    if (!world.turtle_alive(i)) continue;
    const sim::TurtleState tu = world.turtle(i);
    buf += first ? "\n  " : ",\n  ";
    first = false;
    buf += "{\"id\": ";
    append_json_string(buf, names.turtle(i));
    buf += ", \"pos\": [";
    append_number(buf, tu.pos.x);
    buf += ", ";
    append_number(buf, tu.pos.y);
    // Radians inside, degrees in files (Logo convention: 0 is +y, clockwise), in [0, 360).
    const double heading = sim::wrap_degrees(sim::to_degrees(tu.heading));
    buf += "], \"heading\": ";
    append_number(buf, heading);
    buf += "}";
  }
  buf += first ? "]}\n" : "\n]}\n";
  out << buf;
}

}  // namespace turtlegas::formats
