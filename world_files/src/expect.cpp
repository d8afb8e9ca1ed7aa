// SPDX-License-Identifier: MIT
// Reading an `expect` list: its settings ({"until": T}, {"mode": ...}), each entry's kind key, and
// the typed reads of ExpectParser that the kinds' parsers (expect_kinds.cpp) use.
#include "turtlegas/world/expect.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "turtlegas/sim/format.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/sim/suggest.hpp"
#include "turtlegas/world/file_error.hpp"
#include "turtlegas/world/json_read.hpp"

namespace turtlegas::world {
namespace {

using json = nlohmann::json;

std::string num(double v) { return sim::format_number(v); }

// JSON pointers (RFC 6901), as the loader writes them.
std::string at(const std::string& path, std::string_view key) { return json_at(path, key); }
std::string at(const std::string& path, std::size_t index) { return json_at(path, index); }

/// The event kinds a run's log carries (sim's kinds, plus the runtime's touch and fault).
constexpr std::array<std::string_view, 17> event_kinds = {
    "ball-ball",       "ball-wall",     "ball-wall-end", "exit",       "turtle-wall",  "turtle-wall-end", "turtle-turtle",
    "turtle-ball",     "touch",         "fault",         "wall-drawn", "wall-refused", "tag",             "wedged",
    "crushed",         "folded",        "sense"};

/// Whether `id` is `<turtle id>-w<digits>`: the id of a wall a turtle's pen may lay at run time.
bool drawn_wall_id(const std::string& id, const sim::WorldDef& def) {
  for (const auto& t : def.turtles) {
    const std::string head = t.id + "-w";
    if (id.size() > head.size() && id.starts_with(head) &&
        std::all_of(id.begin() + static_cast<std::ptrdiff_t>(head.size()), id.end(),
                    [](char c) { return c >= '0' && c <= '9'; }))
      return true;
  }
  return false;
}

/// The settings an `expect` list may hold besides assertions.
constexpr std::array<std::string_view, 2> setting_keys = {"until", "mode"};

using sim::join_names;
using sim::suggestion;

}  // namespace

// ---- ExpectParser

ExpectParser::ExpectParser(std::string file, const sim::WorldDef& def)
    : json_(std::move(file), JsonReader::Wording::value), def_(def) {}

void ExpectParser::check_keys(const json& entry, const std::string& path, std::string_view kind,
                              std::initializer_list<std::string_view> known) const {
  const std::string* key = unknown_key(entry, known, kind);
  if (!key) return;
  std::vector<std::string_view> takes{kind};
  takes.insert(takes.end(), known.begin(), known.end());
  fail(at(path, *key), "unknown key \"" + *key + "\" in a \"" + std::string(kind) + "\" expectation" +
                           suggestion(*key, known) + " (it takes " + join_names(takes, "\"") +
                           "; keys starting with x- are ignored)");
}

std::string ExpectParser::body_id(const json& v, const std::string& path) const {
  std::string id = string(v, path);  // (not const: returned, it moves)
  for (const auto& t : def_.turtles)
    if (t.id == id) return id;
  for (const auto& b : def_.balls)
    if (b.id == id) return id;
  for (const auto& w : def_.walls)
    if (w.id == id) return id;
  if (def_.arena.boundary == sim::Boundary::walls)  // the arena's walls, with the engine's ids
    for (const sim::WallDef& w : sim::arena_walls(def_.arena))
      if (w.id == id) return id;
  if (drawn_wall_id(id, def_)) return id;  // a wall a turtle's pen may lay while the world runs
  fail(path, "no wall, ball or turtle has id \"" + id + "\" (nor is it <turtle>-w<k>, a wall a turtle may draw)");
}

std::string ExpectParser::turtle_id(const json& v, const std::string& path) const {
  std::string id = string(v, path);  // (not const: returned, it moves)
  for (const auto& t : def_.turtles)
    if (t.id == id) return id;
  fail(path, "no turtle has id \"" + id + "\"");
}

std::vector<std::string> ExpectParser::who(const json& v, const std::string& path) const {
  if (v.is_string() && v.get<std::string>() == "*") return {};
  auto one = [&](const json& x, const std::string& p) {
    std::string id = string(x, p);
    for (const auto& t : def_.turtles)
      if (t.id == id) return id;
    for (const auto& b : def_.balls)
      if (b.id == id) return id;
    fail(p, "no ball or turtle has id \"" + id + "\"");
  };
  if (v.is_string()) return {one(v, path)};
  if (!v.is_array() || v.empty()) fail(path, "who must be \"*\", an id or a non-empty list of ids, got " + v.dump());
  std::vector<std::string> ids;
  for (std::size_t i = 0; i < v.size(); ++i) ids.push_back(one(v[i], at(path, i)));
  return ids;
}

std::string ExpectParser::event_kind(const json& v, const std::string& path) const {
  std::string k = string(v, path);
  if (std::find(event_kinds.begin(), event_kinds.end(), k) == event_kinds.end())
    fail(path, "unknown event kind \"" + k + "\"; known: " + join_names(event_kinds));
  return k;
}

std::optional<double> ExpectParser::at_time(const json& v, const std::string& path) const {
  if (v.is_string() && v.get<std::string>() == "end") return std::nullopt;
  if (!v.is_number()) fail(path, "at must be \"end\" or a time >= 0 in seconds, got " + v.dump());
  return non_negative(v, path);
}

// ---- parse_expect

Expectations parse_expect(const json& expect, const std::string& file, const sim::WorldDef& def) {
  const ExpectParser p(file, def);
  Expectations out;
  out.present = true;
  const std::string path = "/expect";
  if (!expect.is_array())
    p.fail(path, "expect must be a list of expectations, e.g. [{\"until\": 10}, {\"no_event\": \"exit\"}], got " +
                     expect.dump());
  std::vector<std::string_view> all(setting_keys.begin(), setting_keys.end());
  for (const AssertionKind& k : assertion_kinds()) all.push_back(k.key);
  for (std::size_t i = 0; i < expect.size(); ++i) {
    const std::string ep = at(path, i);
    const json& e = expect[i];
    if (!e.is_object()) p.fail(ep, "an expectation must be a JSON object ({\"count\": \"ball-wall\", ...}), got " + e.dump());
    std::vector<std::string> kinds;
    std::string unknown;
    for (const auto& [key, value] : e.items())
      if (std::find(all.begin(), all.end(), key) != all.end()) kinds.push_back(key);
    if (kinds.empty()) {
      for (const auto& [key, value] : e.items())
        if (!key.starts_with("x-")) {
          unknown = key;
          break;
        }
      const std::string where = unknown.empty() ? ep : at(ep, unknown);
      p.fail(where, (unknown.empty() ? std::string("empty expectation")
                                     : "unknown assertion key \"" + unknown + "\"" + suggestion(unknown, all)) +
                        " (an expectation names one of: " + join_names(all) + "; keys starting with x- are ignored)");
    }
    if (kinds.size() > 1)
      p.fail(ep, "an expectation names one kind, this one names \"" + kinds[0] + "\" and \"" + kinds[1] +
                     "\"; put each in its own entry");
    const std::string& kind = kinds[0];
    if (kind == "until") {
      p.check_keys(e, ep, "until", {});
      const double t = p.number(e.at("until"), at(ep, "until"));
      if (!(t > 0.0)) p.fail(at(ep, "until"), "until must be a time > 0 in seconds (got " + num(t) + ")");
      if (out.until) p.fail(ep, "a second {\"until\": ...}; a world has one run length");
      out.until = t;
      continue;
    }
    if (kind == "mode") {
      p.check_keys(e, ep, "mode", {});
      const std::string m = p.string(e.at("mode"), at(ep, "mode"));
      if (const auto mode = sim::mode_from_string(m)) out.modes = {*mode};
      else if (m == "both") out.modes = {sim::Mode::exact, sim::Mode::step};
      else p.fail(at(ep, "mode"), "mode must be \"exact\", \"step\" or \"both\" (got \"" + m + "\")");
      continue;
    }
    const auto& table = assertion_kinds();
    const auto it = std::find_if(table.begin(), table.end(), [&](const AssertionKind& k) { return k.key == kind; });
    out.entries.push_back({i, kind, it->parse(e, ep, p)});
  }
  return out;
}

}  // namespace turtlegas::world
