// SPDX-License-Identifier: MIT
// Whether turtle programs' Turtle::log lines are printed (they are, by default). A command that
// runs a world again to draw it (`render`) turns them off: the run that was recorded printed them
// already (docs/cli.md, render --program-logs).
#pragma once

namespace turtlegas::turtle {

/// Process-wide; set before programs run.
void set_program_logs(bool on);
bool program_logs();

}  // namespace turtlegas::turtle
