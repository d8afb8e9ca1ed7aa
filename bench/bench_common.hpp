// SPDX-License-Identifier: MIT
// What the benchmark programs share: the thread's CPU clock (all of them), number options and the
// project's exit codes, the "--option value" loop and its usage line.
#pragma once

#include <cmath>
#include <ctime>
#include <exception>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/world/world_file.hpp"

namespace turtlegas::bench {

/// CPU time of this thread, seconds. Next to the wall time it shows whether other processes took
/// the core during a measurement (cpu / wall well below 1).
inline double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// The whole of `text` as a finite number > 0, or nothing (for the caller's usage message).
inline std::optional<double> positive_number(const std::string& text) {
  std::size_t used = 0;
  double x = 0.0;
  try {
    x = std::stod(text, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != text.size() || !(x > 0.0) || !std::isfinite(x)) return std::nullopt;
  return x;
}

/// A program's usage line, for argument errors: each throws std::invalid_argument (exit code 2
/// under run_with_exit_codes) with the message and then the usage line.
class Usage {
 public:
  explicit Usage(std::string line) : line_(std::move(line)) {}
  [[noreturn]] void error(const std::string& message) const {
    throw std::invalid_argument(message + "\nusage: " + line_);
  }
  void print(std::ostream& out) const { out << "usage: " << line_ << '\n'; }
  /// The value of `option` as a finite number > 0, or an error naming the option.
  double positive(std::string_view option, const std::string& text) const {
    const std::optional<double> x = positive_number(text);
    if (!x) error(std::string(option) + " needs a positive number, got '" + text + "'");
    return *x;
  }
  /// The value of `option` as a whole number in [lo, hi], or an error naming the option and range.
  long long whole(std::string_view option, const std::string& text, long long lo, long long hi) const {
    const std::optional<double> x = positive_number(text);
    if (!x || *x != std::floor(*x) || *x < static_cast<double>(lo) || *x > static_cast<double>(hi))
      error(std::string(option) + " needs a whole number from " + std::to_string(lo) + " to " + std::to_string(hi) +
            ", got '" + text + "'");
    return static_cast<long long>(*x);
  }

 private:
  std::string line_;
};

/// The value of --mode: exact or step, or an error naming what was given.
inline sim::Mode mode_option(const Usage& usage, const std::string& text) {
  const std::optional<sim::Mode> mode = sim::mode_from_string(text);
  if (!mode) usage.error("--mode takes exact or step, got '" + text + "'");
  return *mode;
}

/// Calls take(option, value) for each "--option value" pair of argv[1..], in order. "-h" or "--help"
/// prints the usage line on standard output and returns false (the program then exits 0); an option
/// without a value is an error (std::invalid_argument, with the usage line).
template <class Take>
bool for_each_option(int argc, char** argv, const Usage& usage, Take take) {
  for (int k = 1; k < argc; k += 2) {
    const std::string option = argv[k];
    if (option == "-h" || option == "--help") {
      usage.print(std::cout);
      return false;
    }
    if (k + 1 == argc) usage.error(option + " needs a value");
    take(option, std::string(argv[k + 1]));
  }
  return true;
}

/// Runs body(argc, argv) with the project's exit codes: its own result, 2 for a bad world file or
/// bad arguments (WorldFileError, std::invalid_argument), 1 for anything else; the message goes to
/// stderr after "PROGRAM: ".
inline int run_with_exit_codes(std::string_view program, int (*body)(int, char**), int argc, char** argv) {
  try {
    return body(argc, argv);
  } catch (const world::WorldFileError& e) {
    std::cerr << program << ": " << e.what() << '\n';
    return 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << program << ": " << e.what() << '\n';
    return 2;
  } catch (const std::exception& e) {
    std::cerr << program << ": " << e.what() << '\n';
    return 1;
  }
}

}  // namespace turtlegas::bench
