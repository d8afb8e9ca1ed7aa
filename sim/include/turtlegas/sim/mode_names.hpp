// SPDX-License-Identifier: MIT
// The names of the two modes, as the command line, `expect` lists, reports and benchmarks spell
// them (the pattern of events.hpp's to_string(EventKind)).
#pragma once

#include <array>
#include <optional>
#include <string_view>

#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim {

/// Every mode's name, in the order of Mode. Views of string literals, so data() is a C string.
inline constexpr std::array<std::string_view, 2> mode_names = {"exact", "step"};

/// "exact" or "step".
constexpr std::string_view to_string(Mode m) { return m == Mode::exact ? mode_names[0] : mode_names[1]; }

/// The mode called `name`, or nullopt for any other word.
constexpr std::optional<Mode> mode_from_string(std::string_view name) {
  if (name == mode_names[0]) return Mode::exact;
  if (name == mode_names[1]) return Mode::step;
  return std::nullopt;
}

}  // namespace turtlegas::sim
