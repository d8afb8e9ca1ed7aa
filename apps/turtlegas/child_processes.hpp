// SPDX-License-Identifier: MIT
// Running parts of a command in child processes of the program itself, a few at a time: one world
// of `turtlegas test` each, or a `turtlegas sweep` worker. A child that crashes (a signal), exits
// without a report, or runs past its time ends alone; the others and the parent go on. SIGINT and
// SIGTERM (signals.hpp) stop them all: a child is in a process group of its own, so a terminal's
// Ctrl-C reaches only the parent, which kills them.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace turtlegas::apps {

/// How one child ended, and what it wrote.
struct ChildResult {
  bool exited = false;     ///< it exited (exit_code is valid)
  int exit_code = -1;
  int signal = 0;          ///< the signal that killed it (0 when it exited)
  bool timed_out = false;  ///< the parent killed it at its timeout
  bool stopped = false;    ///< the parent killed it because it was itself stopped (SIGINT, SIGTERM)
  std::string out, err;    ///< its stdout and stderr
  std::string report;      ///< what it wrote on file descriptor 3 (its report to the parent)
  std::string status;      ///< the last whole line it wrote on descriptor 4 (its progress), or ""
  double seconds = 0.0;    ///< wall clock, from start to end
  /// "exit code 7", "killed by signal 11 (Segmentation fault)", "killed after its 5 s timeout".
  std::string how_it_ended() const;
};

/// A child still running, as the parent's on_tick sees it.
struct RunningChild {
  std::size_t index = 0;
  double seconds = 0.0;  ///< wall clock since it started
  std::string status;    ///< the last whole line it wrote on descriptor 4, or ""
};

/// What the parent hears of its children: each one's end, and now and then those still running.
struct ChildCallbacks {
  std::function<void(std::size_t, ChildResult&&)> on_done;
  /// About every 200 ms, the children still running, in the order they started.
  std::function<void(const std::vector<RunningChild>&)> on_tick;
};

/// The program's own executable (/proc/self/exe), to start children of the same build.
std::string self_executable();

/// Runs `self_executable() args[i]...` for every i, at most `jobs` at once (jobs >= 1), each with
/// stdin /dev/null, stdout, stderr and descriptors 3 and 4 captured, and killed (SIGKILL, its whole
/// process group) once it has run `timeout_seconds` of wall clock (<= 0: no limit). `on_done(i,
/// result)` is called in the parent as each child ends, in the order they end (a child found ended
/// after its timeout had passed counts as timed out, killed or not). At SIGINT or SIGTERM
/// (stop_signal()) no more are started and the running ones are killed, each reported to on_done
/// with `stopped` set; returns that signal, or 0 when every child ran. Throws
/// std::runtime_error when a child cannot be started at all (fork or pipe fail).
int run_children(const std::vector<std::vector<std::string>>& args, std::size_t jobs, double timeout_seconds,
                 const ChildCallbacks& callbacks);

}  // namespace turtlegas::apps
