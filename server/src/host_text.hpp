// SPDX-License-Identifier: MIT
// The host's two text helpers, shared by its host_*.cpp files: a reply's JSON as sent, and a
// number as the logs write it.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "turtlegas/formats/json_text.hpp"

namespace turtlegas::server {

/// One line of JSON, invalid UTF-8 replaced (a client's id or text echoed back stays sendable).
inline std::string dump(const nlohmann::json& j) {
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

/// A number as the event log writes it (shortest round trip).
inline std::string fmt(double v) {
  std::string s;
  formats::append_number(s, v);
  return s;
}

/// A message's "id", or null when it has none.
inline nlohmann::json message_id(const nlohmann::json& m) { return m.contains("id") ? m.at("id") : nlohmann::json(nullptr); }

}  // namespace turtlegas::server
