// SPDX-License-Identifier: MIT
// The protocol's vocabulary (docs/protocol.md): reading and validating a message's fields, the
// error reply, and the encodings of the runtime's remote reports. No I/O here.
#pragma once

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/vec2.hpp"
#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/remote.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::server {

inline constexpr std::string_view protocol_name = "turtlegas/1";
inline constexpr std::string_view server_name = "turtlegas serve 1";

/// A message that fails: the error reply's code, message and JSON pointer (docs/protocol.md,
/// "Errors"). Thrown by the readers below and by the host's handlers; nothing has changed.
struct RequestError : std::runtime_error {
  RequestError(std::string code, const std::string& message, std::string field = {})
      : std::runtime_error(message), code(std::move(code)), field(std::move(field)) {}
  std::string code;
  std::string field;
};

/// {"type": "error", "id": ..., "code": ..., "request": ..., "field": ..., "message": ...}; id and
/// request only when the message had them (a null id is left out).
std::string error_text(std::string_view code, std::string_view message, const nlohmann::json* id = nullptr,
                       std::string_view request = {}, std::string_view field = {});
/// The same, for a message whose JSON object is at hand (its id and type are taken from it).
std::string error_reply(const nlohmann::json& message, const RequestError& e);

/// A message's "id" when it is a number or a string of at most 64 characters, else nullopt
/// (then the message is refused with bad_value by check_id).
void check_id(const nlohmann::json& message);

/// The field readers: `key` of object `m`, with `example` (a whole message) in the message of a
/// wrong or missing value. Path is "/key".
double number_field(const nlohmann::json& m, const char* key, std::string_view example);
std::optional<double> optional_number(const nlohmann::json& m, const char* key, std::string_view example);
std::string string_field(const nlohmann::json& m, const char* key, std::string_view example);
std::optional<bool> optional_bool(const nlohmann::json& m, const char* key, std::string_view example);
/// [x, y] of finite numbers at m[key] (path prefix for nested objects, "/wall").
sim::Vec2 point_field(const nlohmann::json& m, const char* key, std::string_view prefix, std::string_view example);

/// The remote command a "forward" ... "pen" message asks for (docs/protocol.md, "Remote
/// controllers"); throws RequestError for a bad amount or pen mode.
turtle::RemoteCommand read_command(const nlohmann::json& m, std::string_view type);

/// The JSON of a touch: {"sensors": [...], "bits": n, "bearing": b, "what": id, "kind": k, "t": t}.
nlohmann::json touch_json(const turtle::Touch& touch);
/// "up", "line" or "wall".
std::string_view pen_name(bool down, turtle::PenMode mode);
/// The reply for a report of turtle `turtle_id`: a result (with `id` echoed when given), a touch,
/// a message or a fault.
std::string report_text(const turtle::RemoteReport& r, std::string_view turtle_id, const nlohmann::json& id);

/// Whether `given` is `token`, in a time that does not depend on where they differ (a token guessed
/// byte by byte from reply times would otherwise be possible).
bool same_token(std::string_view given, std::string_view token);

/// A save/load name: 1 to 100 of A-Z a-z 0-9 . _ -, not starting with '.'. Throws bad_path.
void check_plain_name(const std::string& name);

}  // namespace turtlegas::server
