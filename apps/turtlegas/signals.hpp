// SPDX-License-Identifier: MIT
// What a run does about signals: Ctrl-C and SIGTERM stop it at its next consistent point, and a
// fatal signal (or an exit()) inside a controller's code is reported, naming what died.
#pragma once

#include <sys/types.h>

#include <string>

namespace turtlegas::apps {

/// From now on SIGINT and SIGTERM do not end the process: they are noted, for the run to see at
/// its next consistent point (stop_signal()), and a line on stderr says so. A second one ends the
/// process at once (its temporary files removed, its child processes killed), for a run that
/// cannot reach that point. `doing` ends the line: "stopping at the next control step and writing
/// the outputs", the default.
void install_stop_signals(const char* doing = nullptr);
/// The first SIGINT or SIGTERM received since install_stop_signals(), or 0.
int stop_signal();
/// The exit code of a run stopped by `sig`: 128 + sig (130 for SIGINT, 143 for SIGTERM), as a
/// shell reports a process killed by it.
int exit_code_for(int sig);
/// "SIGINT", "SIGTERM", ...
const char* signal_name(int sig);

/// A child process group (child_processes.hpp) that a second SIGINT or SIGTERM, or a fatal signal,
/// kills before this process dies: the children are in groups of their own, which a terminal's
/// Ctrl-C does not reach, and would otherwise run on as orphans. Up to 1024 at once.
void note_child_group(pid_t group);
void forget_child_group(pid_t group);

/// From now on a fatal signal (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT) prints one line on stderr
/// naming the world file, the turtle whose program was running and its controller (or that none
/// was) and the simulated time, removes the temporary files of unfinished outputs, and then takes
/// its default action (the process dies of it, as before). An exit() from a controller's code does
/// the same and exits with code 1.
void install_crash_report(const std::string& world);
/// The simulated time the run has reached, for a crash outside any program.
void note_run_time(double t);

}  // namespace turtlegas::apps
