// SPDX-License-Identifier: MIT
#include "turtlegas/server/protocol.hpp"

#include <array>
#include <utility>
#include <cmath>

#include "turtlegas/formats/json_text.hpp"
#include "turtlegas/sim/suggest.hpp"
#include "turtlegas/turtle/json_kind.hpp"

namespace turtlegas::server {
namespace {

using nlohmann::json;

std::string path(const char* key) { return std::string("/") + key; }

[[noreturn]] void missing(const char* key, std::string_view what, std::string_view example) {
  throw RequestError("missing_field", path(key) + " is missing: it must be " + std::string(what) +
                                          "; send e.g. " + std::string(example),
                     path(key));
}

[[noreturn]] void wrong(const char* key, const json& v, std::string_view what, std::string_view example) {
  throw RequestError("wrong_type", path(key) + " must be " + std::string(what) + " (got " + turtle::json_kind(v) +
                                       "); send e.g. " + std::string(example),
                     path(key));
}

}  // namespace

std::string error_text(std::string_view code, std::string_view message, const json* id, std::string_view request,
                       std::string_view field) {
  json e = {{"type", "error"}};
  if (id && !id->is_null()) e["id"] = *id;
  e["code"] = code;
  if (!request.empty()) e["request"] = request;
  if (!field.empty()) e["field"] = field;
  e["message"] = message;
  return e.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string error_reply(const json& message, const RequestError& e) {
  const json* id = nullptr;
  std::string request;
  if (message.is_object()) {
    if (auto it = message.find("id"); it != message.end() && (it->is_number() || (it->is_string() && it->get_ref<const std::string&>().size() <= 64)))
      id = &*it;
    if (auto it = message.find("type"); it != message.end() && it->is_string() && it->get_ref<const std::string&>().size() <= 64)
      request = it->get<std::string>();
  }
  return error_text(e.code, e.what(), id, request, e.field);
}

void check_id(const json& m) {
  const auto it = m.find("id");
  if (it == m.end() || it->is_null() || it->is_number()) return;
  if (it->is_string() && it->get_ref<const std::string&>().size() <= 64) return;
  throw RequestError("bad_value", "/id must be a number or a string of at most 64 characters (it is echoed in the reply)", "/id");
}

double number_field(const json& m, const char* key, std::string_view example) {
  const auto it = m.find(key);
  if (it == m.end()) missing(key, "a number", example);
  if (!it->is_number()) wrong(key, *it, "a number", example);
  const double v = it->get<double>();
  if (!std::isfinite(v)) throw RequestError("bad_value", path(key) + " must be finite", path(key));
  return v;
}

std::optional<double> optional_number(const json& m, const char* key, std::string_view example) {
  if (!m.contains(key)) return std::nullopt;
  return number_field(m, key, example);
}

std::string string_field(const json& m, const char* key, std::string_view example) {
  const auto it = m.find(key);
  if (it == m.end()) missing(key, "a string", example);
  if (!it->is_string()) wrong(key, *it, "a string", example);
  return it->get<std::string>();
}

std::optional<bool> optional_bool(const json& m, const char* key, std::string_view example) {
  const auto it = m.find(key);
  if (it == m.end()) return std::nullopt;
  if (!it->is_boolean()) wrong(key, *it, "true or false", example);
  return it->get<bool>();
}

sim::Vec2 point_field(const json& m, const char* key, std::string_view prefix, std::string_view example) {
  const std::string p = std::string(prefix) + "/" + key;
  const auto it = m.find(key);
  if (it == m.end())
    throw RequestError("missing_field", p + " is missing: it must be [x, y]; send e.g. " + std::string(example), p);
  if (!it->is_array() || it->size() != 2 || !(*it)[0].is_number() || !(*it)[1].is_number())
    throw RequestError("wrong_type", p + " must be [x, y], two numbers (got " + turtle::json_kind(*it) + "); send e.g. " + std::string(example), p);
  const sim::Vec2 v{(*it)[0].get<double>(), (*it)[1].get<double>()};
  if (!std::isfinite(v.x) || !std::isfinite(v.y)) throw RequestError("bad_value", p + " must be finite", p);
  return v;
}

turtle::RemoteCommand read_command(const json& m, std::string_view type) {
  using K = turtle::RemoteCommand::Kind;
  turtle::RemoteCommand c;
  if (type == "pen") {
    constexpr std::string_view ex = R"({"type": "pen", "turtle": "t1", "down": true, "mode": "line"})";
    const std::optional<bool> down = optional_bool(m, "down", ex);
    if (!down) missing("down", "true or false", ex);
    c.kind = *down ? K::pen_down : K::pen_up;
    if (m.contains("mode")) {
      const std::string mode = string_field(m, "mode", ex);
      if (mode != "line" && mode != "wall")
        throw RequestError("bad_value", "/mode must be \"line\" or \"wall\" (got \"" + mode + "\")", "/mode");
      c.pen = mode == "wall" ? turtle::PenMode::wall : turtle::PenMode::line;
    }
    return c;
  }
  if (type == "sense") {
    c.kind = K::sense;
    c.sensor = string_field(m, "sensor", R"({"type": "sense", "turtle": "t1", "sensor": "ir"})");
    return c;
  }
  if (type == "camera") {
    c.kind = K::camera;
    c.sensor = string_field(m, "sensor", R"({"type": "camera", "turtle": "t1", "sensor": "cam"})");
    return c;
  }
  c.kind = *turtle::remote_command_kind(type);
  if (const auto keys = turtle::steer_keys(c.kind); !keys.empty()) {
    // arc, drive, wheels: named numbers, as Turtle::arc, drive and wheels take them.
    const std::string ex = c.kind == K::arc     ? R"({"type": "arc", "turtle": "t1", "radius": 50, "degrees": 90})"
                           : c.kind == K::drive ? R"({"type": "drive", "turtle": "t1", "v": 20, "omega": 45, "seconds": 2})"
                                                : R"({"type": "wheels", "turtle": "t1", "left": 20, "right": 10, "seconds": 2})";
    for (std::size_t k = 0; k < keys.size(); ++k) c.steer[k] = number_field(m, std::string(keys[k]).c_str(), ex);
    if (c.kind == K::arc && c.steer[0] < 0.0)
      throw RequestError("bad_value", "/radius must be >= 0 (got " + json(c.steer[0]).dump() +
                                          "); negative degrees turn left, and drive with v < 0 goes backwards", "/radius");
    if (c.kind != K::arc && c.steer[2] < 0.0)
      throw RequestError("bad_value", "/seconds must be >= 0 (got " + json(c.steer[2]).dump() + ")", "/seconds");
    return c;
  }
  if (turtle::takes_amount(c.kind)) {
    const std::string ex = "{\"type\": \"" + std::string(type) + "\", \"turtle\": \"t1\", \"amount\": " +
                           (c.kind == K::wait ? "0.5" : c.kind == K::left || c.kind == K::right ? "90" : "100") + "}";
    c.amount = number_field(m, "amount", ex);
    if (c.amount < 0.0)
      throw RequestError("bad_value", "/amount must be >= 0 (got " + json(c.amount).dump() + "); " +
                                          (c.kind == K::forward ? "use back to go backwards" : c.kind == K::back ? "use forward" : c.kind == K::left ? "use right" : c.kind == K::right ? "use left" : "a wait is a time >= 0"),
                         "/amount");
  }
  return c;
}

json touch_json(const turtle::Touch& touch) {
  json names = json::array();
  if (touch.sensor_names)
    for (std::size_t k = 0; k < touch.sensor_names->size(); ++k)
      if (touch.fired(k)) names.push_back((*touch.sensor_names)[k]);
  const double bearing = touch.bearing == 0.0 ? 0.0 : touch.bearing;  // no "-0.0"
  return {{"sensors", names}, {"bits", touch.sensors}, {"bearing", bearing}, {"what", touch.what},
          {"kind", touch.kind}, {"t", touch.t}};
}

std::string_view pen_name(bool down, turtle::PenMode mode) {
  if (!down) return "up";
  return mode == turtle::PenMode::wall ? "wall" : "line";
}

namespace {

// A double as nlohmann's dump writes the value: the shortest text that reads back to it, with
// ".0" on integral values so that clients parse a float (Python's json gives an int otherwise).
void append_double(std::string& out, double v) {
  if (v == 0.0) v = 0.0;  // no "-0.0"
  const std::size_t from = out.size();
  formats::append_number(out, v);
  if (out.find_first_of(".en", from) == std::string::npos) out += ".0";
}

void append_key(std::string& out, std::string_view key) {
  out += '"';
  out += key;
  out += "\":";
}

void append_touch(std::string& out, const turtle::Touch& touch) {
  out += "{\"bearing\":";
  append_double(out, touch.bearing);
  out += ",\"bits\":";
  out += std::to_string(touch.sensors);
  out += ",\"kind\":";
  formats::append_json_string(out, touch.kind);
  out += ",\"sensors\":[";
  bool first = true;
  if (touch.sensor_names)
    for (std::size_t k = 0; k < touch.sensor_names->size(); ++k)
      if (touch.fired(k)) {
        if (!first) out += ',';
        first = false;
        formats::append_json_string(out, (*touch.sensor_names)[k]);
      }
  out += "],\"t\":";
  append_double(out, touch.t);
  out += ",\"what\":";
  formats::append_json_string(out, touch.what);
  out += '}';
}

}  // namespace

// Written by hand, not through a json object: a remote turtle's every command is answered by one
// of these, and building and dumping the object cost ~35,000 instructions a report (callgrind,
// docs/performance.md "The world server"). Keys in nlohmann's (alphabetical) order, numbers as it
// writes them, so that the text is what `touch_json` and dump() gave (tests/server/cpp/report_test).
std::string report_text(const turtle::RemoteReport& r, std::string_view turtle_id, const json& id) {
  using Kind = turtle::RemoteReport::Kind;
  std::string out;
  out.reserve(320);
  out += '{';
  switch (r.kind) {
    case Kind::result:
      if (turtle::takes_amount(r.command.kind)) {
        append_key(out, "amount");
        append_double(out, r.command.amount);
        out += ',';
      }
      if (const auto keys = turtle::steer_keys(r.command.kind); !keys.empty()) {
        // arc, drive, wheels: the command's numbers, by name (sorted, as dump() writes them).
        std::array<std::size_t, 3> order{0, 1, 2};
        for (std::size_t i = 1; i < keys.size(); ++i)  // (an insertion sort of at most three)
          for (std::size_t j = i; j > 0 && keys[order[j]] < keys[order[j - 1]]; --j) std::swap(order[j], order[j - 1]);
        append_key(out, "args");
        out += '{';
        for (std::size_t k = 0; k < keys.size(); ++k) {
          if (k > 0) out += ',';
          append_key(out, keys[order[k]]);
          append_double(out, r.command.steer[order[k]]);
        }
        out += "},";
      }
      append_key(out, "command");
      formats::append_json_string(out, turtle::to_string(r.command.kind));
      out += ',';
      append_key(out, "done");
      append_double(out, r.result.done());
      out += ',';
      if (!id.is_null()) {
        append_key(out, "id");
        out += id.dump(-1, ' ', false, json::error_handler_t::replace);
        out += ',';
      }
      if (r.command.kind == turtle::RemoteCommand::Kind::sense || r.command.kind == turtle::RemoteCommand::Kind::camera) {
        // Every ray, as Turtle::scan reads it: distance null past the range, what and kind then null too.
        // A camera's pixels (Turtle::camera) also carry their colour, the background's past the range.
        append_key(out, "readings");
        out += '[';
        for (std::size_t k = 0; k < r.readings.size(); ++k) {
          const turtle::Reading& rd = r.readings[k];
          if (k > 0) out += ',';
          out += "{\"bearing\":";
          append_double(out, rd.bearing);
          if (!rd.colour.empty()) {
            out += ",\"colour\":";
            formats::append_json_string(out, rd.colour);
          }
          out += ",\"distance\":";
          if (rd.hit()) append_double(out, rd.distance);
          else out += "null";
          out += ",\"kind\":";
          if (rd.hit()) formats::append_json_string(out, rd.kind);
          else out += "null";
          out += ",\"what\":";
          if (rd.hit()) formats::append_json_string(out, rd.what);
          else out += "null";
          out += '}';
        }
        out += "],";
        append_key(out, "sensor");
        formats::append_json_string(out, r.command.sensor);
        out += ',';
      }
      append_key(out, "state");
      out += "{\"heading\":";
      append_double(out, r.heading);
      out += r.it ? ",\"it\":true" : ",\"it\":false";
      out += ",\"odometer\":";
      append_double(out, r.odometer);
      out += ",\"pen\":";
      formats::append_json_string(out, pen_name(r.pen_down, r.pen_mode));
      if (r.position) {
        out += ",\"pos\":[";
        append_double(out, r.position->x);
        out += ',';
        append_double(out, r.position->y);
        out += ']';
      }
      out += "},";
      break;
    case Kind::touch:
    case Kind::fault:
      break;
    case Kind::message:
      append_key(out, "data");
      out += r.message.data.dump(-1, ' ', false, json::error_handler_t::replace);
      out += ',';
      break;
  }
  if (r.kind == Kind::fault) {
    append_key(out, "message");
    formats::append_json_string(out, r.fault);
    out += ',';
  }
  if (r.kind == Kind::message) {
    append_key(out, "sent");
    append_double(out, r.message.t);
    out += ',';
  }
  append_key(out, "step");
  out += std::to_string(r.step);
  out += ',';
  append_key(out, "t");
  append_double(out, r.t);
  out += ',';
  if (r.kind == Kind::touch || (r.kind == Kind::result && r.result.touched())) {
    append_key(out, "touch");
    append_touch(out, r.kind == Kind::touch ? r.touch : r.result.touch());
    out += ',';
  }
  if (r.kind == Kind::result) out += r.result.touched() ? "\"touched\":true," : "\"touched\":false,";
  append_key(out, "turtle");
  formats::append_json_string(out, turtle_id);
  out += ",\"type\":";
  static constexpr std::string_view types[] = {"\"result\"", "\"touch\"", "\"message\"", "\"fault\""};
  switch (r.kind) {
    case Kind::result: out += types[0]; break;
    case Kind::touch: out += types[1]; break;
    case Kind::message: out += types[2]; break;
    case Kind::fault: out += types[3]; break;
  }
  out += '}';
  return out;
}

void check_plain_name(const std::string& name) {
  bool ok = !name.empty() && name.size() <= 100 && name[0] != '.';
  for (char c : name)
    ok = ok && ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '-');
  if (!ok)
    throw RequestError("bad_path", "/file must be a plain name in the save directory: 1 to 100 of A-Z a-z 0-9 . _ -, not starting with '.' (no '/', no '..'); e.g. \"snap.json\"", "/file");
}

bool same_token(std::string_view given, std::string_view token) {
  // Every byte of `given` is compared, whatever differs first; the time tells only its length.
  if (token.empty()) return given.empty();
  volatile unsigned char diff = given.size() == token.size() ? 0 : 1;
  for (std::size_t i = 0; i < given.size(); ++i) diff = diff | static_cast<unsigned char>(given[i] ^ token[i % token.size()]);
  return diff == 0;
}

}  // namespace turtlegas::server
