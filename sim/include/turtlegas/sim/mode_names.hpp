// SPDX-License-Identifier: MIT
// The names of the two modes, as the command line, `expect` lists, reports and benchmarks spell
// them, and of the arena's boundaries, as world files, `check`, the server and the observables
// spell them (the pattern of events.hpp's to_string(EventKind)).
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

/// Every boundary's name, in the order of Boundary (world files' "arena": {"boundary": ...}).
inline constexpr std::array<std::string_view, 3> boundary_names = {"none", "walls", "periodic"};

/// "none", "walls" or "periodic".
constexpr std::string_view to_string(Boundary b) {
  switch (b) {
    case Boundary::none: return boundary_names[0];
    case Boundary::walls: return boundary_names[1];
    case Boundary::periodic: return boundary_names[2];
  }
  return boundary_names[0];
}

/// The boundary called `name`, or nullopt for any other word.
constexpr std::optional<Boundary> boundary_from_string(std::string_view name) {
  if (name == boundary_names[0]) return Boundary::none;
  if (name == boundary_names[1]) return Boundary::walls;
  if (name == boundary_names[2]) return Boundary::periodic;
  return std::nullopt;
}

}  // namespace turtlegas::sim
