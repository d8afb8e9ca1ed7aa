// SPDX-License-Identifier: MIT
#include "option_checks.hpp"

#include <cmath>

#include "cli_common.hpp"

namespace turtlegas::apps {

void check_stack_kib(std::size_t kib) {
  // The bounds of `run --stack-kib`: below 16 KiB the API's own frames do not fit.
  check_count("--stack-kib", kib, 16, 1024 * 1024);
}

void check_program_budget(double seconds) {
  if (!std::isfinite(seconds) || seconds <= 0.0)
    throw BadInput("--program-budget must be a finite time > 0 in seconds of wall clock (got " + fmt(seconds) + ")");
}

void check_count(const std::string& option, std::size_t value, std::size_t lo, std::size_t hi) {
  if (value < lo || value > hi)
    throw BadInput(option + " must be from " + std::to_string(lo) + " to " + std::to_string(hi) + " (got " +
                   std::to_string(value) + ")");
}

void check_seconds(const std::string& option, double seconds, bool zero_allowed) {
  if (!std::isfinite(seconds) || seconds < 0.0 || (!zero_allowed && seconds == 0.0))
    throw BadInput(option + " must be a finite time " + (zero_allowed ? ">= 0 (0: no limit)" : "> 0") +
                   " in seconds (got " + fmt(seconds) + ")");
}

}  // namespace turtlegas::apps
