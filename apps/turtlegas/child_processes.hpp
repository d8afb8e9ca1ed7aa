// SPDX-License-Identifier: MIT
// Running parts of a command in child processes of the program itself, a few at a time: one world
// of `turtlegas test` each, or a `turtlegas sweep` worker. A child that crashes (a signal), exits
// without a report, or runs past its time ends alone; the others and the parent go on.
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
  std::string out, err;    ///< its stdout and stderr
  std::string report;      ///< what it wrote on file descriptor 3 (its report to the parent)
  double seconds = 0.0;    ///< wall clock, from start to end
  /// "exit code 7", "killed by signal 11 (Segmentation fault)", "killed after its 5 s timeout".
  std::string how_it_ended() const;
};

/// The program's own executable (/proc/self/exe), to start children of the same build.
std::string self_executable();

/// Runs `self_executable() args[i]...` for every i, at most `jobs` at once (jobs >= 1), each with
/// stdin /dev/null, stdout, stderr and descriptor 3 captured, and killed (SIGKILL, its whole
/// process group) once it has run `timeout_seconds` of wall clock (<= 0: no limit). `on_done(i,
/// result)` is called in the parent as each child ends, in the order they end (a child found ended
/// after its timeout had passed counts as timed out, killed or not). Throws
/// std::runtime_error when a child cannot be started at all (fork or pipe fail).
void run_children(const std::vector<std::vector<std::string>>& args, std::size_t jobs, double timeout_seconds,
                  const std::function<void(std::size_t, ChildResult&&)>& on_done);

}  // namespace turtlegas::apps
