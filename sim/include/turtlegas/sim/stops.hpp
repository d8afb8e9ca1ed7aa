// SPDX-License-Identifier: MIT
// How a long advance_to ends early, the same for the 2-D World and the 3-D World3: an event limit
// set beforehand, or a poll the caller set (a signal, a wall clock: sim/ has neither) saying stop.
#pragma once

#include <stdexcept>

namespace turtlegas::sim {

/// advance_to ran into the bound set with set_event_limit.
struct EventLimitReached : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// advance_to was stopped because the poll set with set_stop_poll returned true.
struct StopRequested : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace turtlegas::sim
