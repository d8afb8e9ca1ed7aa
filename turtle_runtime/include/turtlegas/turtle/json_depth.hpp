// SPDX-License-Identifier: MIT
// The nesting limit of every JSON text turtlegas reads: world files, protocol messages, input
// logs, recordings, checkpoints, sweep specs and journals. It lives here, in the lowest layer that
// holds JSON (a controller's params), so that every reader above includes the one helper.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace turtlegas::turtle {

/// Arrays and objects nested deeper than this are refused before they are parsed: nlohmann::json
/// copies, compares, dumps and destroys values recursively, so a text nested 100,000 deep (200 KB)
/// overflows the stack wherever such a value goes next. Real inputs nest fewer than 10 levels.
inline constexpr std::size_t max_json_depth = 512;

/// Why `text` nests too deep ("nested more than 512 levels deep (at byte 1024); turtlegas reads
/// JSON nested at most 512 levels"), or nothing. Strings are skipped (their brackets do not
/// count); the text need not be valid JSON (the parser says what else is wrong). One pass, no
/// allocation unless it fails.
inline std::optional<std::string> json_too_deep(std::string_view text) {
  std::size_t depth = 0;
  bool in_string = false, escaped = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
      continue;
    }
    switch (c) {
      case '"': in_string = true; break;
      case '[':
      case '{':
        if (++depth > max_json_depth)
          return "nested more than " + std::to_string(max_json_depth) + " levels deep (at byte " + std::to_string(i) +
                 "); turtlegas reads JSON nested at most " + std::to_string(max_json_depth) + " levels";
        break;
      case ']':
      case '}':
        if (depth > 0) --depth;
        break;
      default: break;
    }
  }
  return std::nullopt;
}

}  // namespace turtlegas::turtle
