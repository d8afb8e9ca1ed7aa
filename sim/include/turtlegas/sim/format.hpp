// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <charconv>
#include <string>

#include "turtlegas/sim/vec2.hpp"

// Numbers in messages: shared by validate(), the world-file loader and `expect`.
namespace turtlegas::sim {

/// The shortest decimal that reads back as the same double ("-1", not "-1.000000").
inline std::string format_number(double v) {
  std::array<char, 32> buf{};
  auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return std::string(buf.data(), r.ptr);
}

/// "[x, y]". Appended piecewise: GCC 12 gives a false -Wrestrict for "literal" + std::string
/// (bug 105329).
inline std::string format_vec(Vec2 v) {
  std::string s = "[";
  s += format_number(v.x);
  s += ", ";
  s += format_number(v.y);
  s += ']';
  return s;
}

}  // namespace turtlegas::sim
