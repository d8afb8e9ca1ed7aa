// SPDX-License-Identifier: MIT
// The event log (design.md, "--events"): one JSON object per line, in time order,
//   {"t": 1.25, "kind": "ball-ball", "a": "b1", "b": "b2"}
// with "sensors" and "bearing" on `touch` lines and "message" on `fault` lines. One writer for the
// engine's own events (sim::Event, named by turtle/event_names.hpp) and for the world server's
// (turtle::LogEvent), so a scene writes the same line for the same event whichever ran it.
#pragma once

#include <cstddef>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "turtlegas/formats/json_text.hpp"
#include "turtlegas/sim/events.hpp"
#include "turtlegas/turtle/event_names.hpp"
#include "turtlegas/turtle/log_event.hpp"

namespace turtlegas::formats {

/// One line's fields; sensors (with bearing) only on touch lines, message only when non-empty.
struct EventLine {
  double t = 0.0;
  std::string_view kind;
  std::string_view a;
  std::optional<std::string_view> b;
  std::optional<std::string_view> c;  ///< wedged, crushed: the second obstacle
  const std::vector<std::string>* sensors = nullptr;
  double bearing = 0.0;  ///< degrees clockwise from the heading to the contact point, [0, 360)
  std::string_view message;
  std::string_view extra;  ///< more members, JSON text without braces (`view` events)
};

/// Appends one line of the log, newline included.
inline void append_event(std::string& out, const EventLine& e) {
  out += "{\"t\": ";
  append_number(out, e.t);
  out += ", \"kind\": ";
  append_json_string(out, e.kind);
  out += ", \"a\": ";
  append_json_string(out, e.a);
  if (e.b) {
    out += ", \"b\": ";
    append_json_string(out, *e.b);
  }
  if (e.c) {
    out += ", \"c\": ";
    append_json_string(out, *e.c);
  }
  if (e.sensors) {
    out += ", \"sensors\": [";
    for (std::size_t k = 0; k < e.sensors->size(); ++k) {
      if (k > 0) out += ", ";
      append_json_string(out, (*e.sensors)[k]);
    }
    out += "], \"bearing\": ";
    append_number(out, e.bearing);
  }
  if (!e.message.empty()) {
    out += ", \"message\": ";
    append_json_string(out, e.message);
  }
  if (!e.extra.empty()) {
    out += ", ";
    out += e.extra;
  }
  out += "}\n";
}

/// The line of an engine event, its bodies named by `names` (turtle/event_names.hpp).
template <class Names>
EventLine event_line(const sim::Event& e, const Names& names) {
  const turtle::EventIds ids = turtle::name_event(e, names);
  EventLine line;
  line.t = e.t;
  line.kind = sim::to_string(e.kind);
  line.a = ids.a;
  line.b = ids.b;
  line.c = ids.c;
  return line;
}

/// The line of a world server's event. An exit or a fault names no second body (empty b).
inline EventLine event_line(const turtle::LogEvent& e) {
  EventLine line;
  line.t = e.t;
  line.kind = e.kind;
  line.a = e.a;
  if (!e.b.empty()) line.b = e.b;
  if (!e.c.empty()) line.c = e.c;
  if (e.kind == "touch") {
    line.sensors = &e.sensors;
    line.bearing = e.bearing;
  }
  line.message = e.message;
  line.extra = e.extra;
  return line;
}

/// Writes the log in chunks while a run goes on: each write() appends its events' lines.
class EventLogWriter {
 public:
  explicit EventLogWriter(std::ostream& out) : out_(out) {}

  /// The engine's events, named by `names` (RunNames, say).
  template <class Names>
  void write(std::span<const sim::Event> events, const Names& names) {
    buf_.clear();
    for (const sim::Event& e : events) append_event(buf_, event_line(e, names));
    flush();
  }
  /// The world server's events.
  void write(std::span<const turtle::LogEvent> events) {
    buf_.clear();
    for (const turtle::LogEvent& e : events) append_event(buf_, event_line(e));
    flush();
  }

 private:
  void flush() { out_.write(buf_.data(), static_cast<std::streamsize>(buf_.size())); }
  std::ostream& out_;
  std::string buf_;
};

}  // namespace turtlegas::formats
