// SPDX-License-Identifier: MIT
// The error every reader of a world file throws: the loader, `expect` and the `game` key.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

namespace turtlegas::world {

/// A world file that cannot be used. what() is one line:
/// `FILE: /balls/3/radius: radius must be > 0 (got -1)`, `FILE: MESSAGE` when no JSON path applies,
/// or `FILE:LINE:COLUMN: invalid JSON: ...` for a syntax error.
struct WorldFileError : std::runtime_error {
  WorldFileError(std::string file, std::string json_path, std::string reason, std::size_t line = 0,
                 std::size_t column = 0);

  std::string file;       ///< the file name as given (for messages)
  std::string json_path;  ///< JSON pointer to the offending value (`/balls/3/radius`), or empty
  std::string reason;     ///< the message without the file and path prefix
  std::size_t line = 0;   ///< 1-based, for JSON syntax errors only (0 otherwise)
  std::size_t column = 0; ///< 1-based, in bytes, for JSON syntax errors only (0 otherwise)
};

}  // namespace turtlegas::world
