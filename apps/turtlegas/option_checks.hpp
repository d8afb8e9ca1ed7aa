// SPDX-License-Identifier: MIT
// Range checks of numeric command-line options: each throws BadInput (exit code 2) naming the
// option, the range and what it got. Used by test, tag and sweep.
#pragma once

#include <cstddef>
#include <string>

namespace turtlegas::apps {

/// A program stack of 16 KiB to 1 GiB.
void check_stack_kib(std::size_t kib);
/// A finite wall-clock budget > 0 seconds.
void check_program_budget(double seconds);
/// An integer count in [lo, hi].
void check_count(const std::string& option, std::size_t value, std::size_t lo, std::size_t hi);
/// A finite number of seconds, > 0 (or >= 0 when zero_allowed: "no limit").
void check_seconds(const std::string& option, double seconds, bool zero_allowed);

}  // namespace turtlegas::apps
