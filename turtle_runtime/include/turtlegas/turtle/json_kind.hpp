// SPDX-License-Identifier: MIT
// What a JSON value is, in the words every message of the house uses ("view.rotate must be true
// or false, got a string"): in the lowest layer that reads JSON (views, parse_view), for the
// world-file reader, the server's protocol and the views alike.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace turtlegas::turtle {

/// "null", "true or false", "a number", "a string", "an array" or "an object" (and nlohmann's
/// own name, with "a", for its binary and discarded values).
inline std::string json_kind(const nlohmann::json& v) {
  if (v.is_null()) return "null";
  if (v.is_boolean()) return "true or false";
  if (v.is_number()) return "a number";
  if (v.is_string()) return "a string";
  if (v.is_array()) return "an array";
  if (v.is_object()) return "an object";
  return std::string("a ") + v.type_name();
}

}  // namespace turtlegas::turtle
