// SPDX-License-Identifier: MIT
#include "turtlegas/world/file_error.hpp"

#include <utility>

namespace turtlegas::world {
namespace {

std::string prefix(const std::string& file, const std::string& path, const std::string& reason, std::size_t line,
                   std::size_t column) {
  if (line > 0) return file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + reason;
  if (!path.empty()) return file + ": " + path + ": " + reason;
  return file + ": " + reason;
}

}  // namespace

WorldFileError::WorldFileError(std::string file_, std::string json_path_, std::string reason_, std::size_t line_,
                               std::size_t column_)
    : std::runtime_error(prefix(file_, json_path_, reason_, line_, column_)),
      file(std::move(file_)),
      json_path(std::move(json_path_)),
      reason(std::move(reason_)),
      line(line_),
      column(column_) {}

}  // namespace turtlegas::world
