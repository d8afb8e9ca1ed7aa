// SPDX-License-Identifier: MIT
// One line of a run's event log as the world server and its game produce it (ids resolved).
#pragma once

#include <string>
#include <vector>

namespace turtlegas::turtle {

/// One line of the run's event log, with ids resolved; `touch` events carry sensors and bearing.
struct LogEvent {
  double t = 0.0;
  std::string kind;
  std::string a;
  std::string b;
  std::vector<std::string> sensors;  ///< touch only
  double bearing = 0.0;              ///< touch only, degrees
  std::string message;               ///< `fault` events: what went wrong
  std::string c;                     ///< `wedged`, `crushed`: the second obstacle
  /// More members for the line, as JSON text without braces (`view` events: `"op": "open",
  /// "view": {...}`); empty for every other kind.
  std::string extra;
};

}  // namespace turtlegas::turtle
