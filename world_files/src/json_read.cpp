// SPDX-License-Identifier: MIT
#include "turtlegas/world/json_read.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "turtlegas/sim/format.hpp"
#include "turtlegas/sim/suggest.hpp"
#include "turtlegas/world/file_error.hpp"

namespace turtlegas::world {

using json = nlohmann::json;

std::string json_token(std::string_view key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

std::string json_at(const std::string& path, std::string_view key) { return path + "/" + json_token(key); }
std::string json_at(const std::string& path, std::size_t index) { return path + "/" + std::to_string(index); }

const std::string* unknown_key(const json& obj, std::initializer_list<std::string_view> known, std::string_view also) {
  if (!obj.is_object()) return nullptr;
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const std::string& key = it.key();  // the object's own key: it outlives the loop
    if (key.starts_with("x-") || (!also.empty() && key == also) ||
        std::find(known.begin(), known.end(), key) != known.end())
      continue;
    return &key;
  }
  return nullptr;
}

void JsonReader::fail(const std::string& path, const std::string& reason) const {
  throw WorldFileError(file_, path, reason);
}

std::string JsonReader::got(const json& v) const { return wording_ == Wording::kind ? json_kind(v) : v.dump(); }

void JsonReader::expect_object(const json& v, const std::string& path, std::string_view what) const {
  if (!v.is_object()) fail(path, std::string(what) + " must be a JSON object ({...}), got " + got(v));
}

void JsonReader::expect_array(const json& v, const std::string& path, std::string_view what) const {
  if (!v.is_array()) fail(path, std::string(what) + " must be a JSON array ([...]), got " + got(v));
}

void JsonReader::check_keys(const json& obj, const std::string& path, std::string_view what,
                            std::initializer_list<std::string_view> known, bool suggest) const {
  const std::string* key = unknown_key(obj, known);
  if (!key) return;
  std::string reason = "unknown key \"" + *key + "\" in " + std::string(what);
  if (suggest) reason += sim::suggestion(*key, known);
  reason += " (known keys: " + sim::join_names(known) + "; keys starting with x- are ignored)";
  fail(json_at(path, *key), reason);
}

const json* JsonReader::find(const json& obj, std::string_view key) const {
  auto it = obj.find(key);
  return it == obj.end() ? nullptr : &*it;
}

const json& JsonReader::require(const json& obj, const std::string& path, std::string_view key,
                                std::string_view what) const {
  if (const json* v = find(obj, key)) return *v;
  fail(path, std::string(what) + " needs \"" + std::string(key) + "\"");
}

double JsonReader::number(const json& v, const std::string& path) const {
  if (!v.is_number()) fail(path, "expected a number, got " + got(v));
  const double d = v.get<double>();
  if (!std::isfinite(d))
    fail(path, wording_ == Wording::kind ? "expected a finite number, got " + sim::format_number(d)
                                         : std::string("expected a finite number"));
  return d;
}

double JsonReader::positive(const json& v, const std::string& path, std::string_view name) const {
  const double d = number(v, path);
  if (!(d > 0.0)) fail(path, std::string(name) + " must be > 0 (got " + sim::format_number(d) + ")");
  return d;
}

double JsonReader::non_negative(const json& v, const std::string& path) const {
  const double d = number(v, path);
  if (d < 0.0) fail(path, "expected a number >= 0, got " + sim::format_number(d));
  return d;
}

std::uint64_t JsonReader::natural(const json& v, const std::string& path) const {
  if (v.is_number_unsigned()) return v.get<std::uint64_t>();
  if (v.is_number_integer()) fail(path, "expected an integer >= 0, got " + std::to_string(v.get<std::int64_t>()));
  if (v.is_number_float()) {
    const double d = v.get<double>();
    if (d >= 0.0 && d < 0x1.0p64 && std::floor(d) == d) return static_cast<std::uint64_t>(d);
    fail(path, "expected an integer >= 0, got " + sim::format_number(d));
  }
  fail(path, "expected an integer >= 0, got " + got(v));
}

bool JsonReader::boolean(const json& v, const std::string& path) const {
  if (!v.is_boolean()) fail(path, "expected true or false, got " + got(v));
  return v.get<bool>();
}

std::string JsonReader::string(const json& v, const std::string& path) const {
  if (!v.is_string()) fail(path, "expected a string, got " + got(v));
  return v.get<std::string>();
}

sim::Vec2 JsonReader::vec2(const json& v, const std::string& path) const {
  const std::string shape = "expected [x, y] (an array of 2 numbers), got ";
  if (wording_ == Wording::kind) {
    if (!v.is_array()) fail(path, shape + json_kind(v));
    if (v.size() != 2) fail(path, shape + "an array of " + std::to_string(v.size()));
  } else if (!v.is_array() || v.size() != 2) {
    fail(path, shape + v.dump());
  }
  return {number(v[0], json_at(path, 0)), number(v[1], json_at(path, 1))};
}

}  // namespace turtlegas::world
