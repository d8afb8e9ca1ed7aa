// SPDX-License-Identifier: MIT
// Checking the errors the world-file readers raise: the file, the JSON path, the reason, and the
// one-line message built from them.
#pragma once

#include <stdexcept>
#include <string>

#include <catch2/catch.hpp>

#include "turtlegas/world/world_file.hpp"

namespace turtlegas::test {

/// The WorldFileError that parse(text) raises; fails the test if it parses.
template <class Parse>
world::WorldFileError error_of(Parse&& parse, const std::string& text) {
  try {
    parse(text);
  } catch (const world::WorldFileError& e) {
    return e;
  }
  FAIL("expected a WorldFileError for: " << text);
  throw std::logic_error("unreachable");
}

inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace turtlegas::test

/// The error of parsing `text` (with the file's own error_of(text)) is at JSON path `path`, its
/// reason contains `part`, and its message is "w.json: PATH: REASON".
#define CHECK_ERROR(text, path, part)                                                                   \
  do {                                                                                                  \
    const turtlegas::world::WorldFileError e_ = error_of(text);                                         \
    INFO(e_.what());                                                                                    \
    CHECK(e_.file == "w.json");                                                                         \
    CHECK(e_.json_path == (path));                                                                      \
    CHECK(turtlegas::test::contains(e_.reason, (part)));                                                \
    CHECK(std::string(e_.what()) ==                                                                     \
          "w.json: " + std::string(path).append(std::string(path).empty() ? "" : ": ") + e_.reason);    \
  } while (false)
