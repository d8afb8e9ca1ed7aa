// SPDX-License-Identifier: MIT
// Scripted test worlds: a world file's `expect` list, and running a scene against it.
//
// An `expect` entry is a JSON object whose *kind key* says what it asserts ({"count": "ball-wall",
// "min": 10}); the other keys are that kind's options. Two entries are settings, not assertions:
// {"until": T} (the run's length, required by `turtlegas test`) and {"mode": "exact"|"step"|"both"}.
// The assertion kinds are an explicit table in expect_kinds.cpp (assertion_kinds()): a new kind is one
// class and one line there. docs/worlds.md, "Scripted test worlds", is the user's reference.
// Running a scene against its list is scenario.hpp's.
#pragma once

#include <cstddef>
#include <functional>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/log_event.hpp"
#include "turtlegas/world/json_read.hpp"
#include "turtlegas/world/run_view.hpp"

namespace turtlegas::world {

/// One run's checking of one assertion: fed every event and every control step, asked at the end.
class Check {
 public:
  virtual ~Check() = default;
  virtual void on_event(const turtle::LogEvent&, const RunView&) {}
  /// At t = 0 and at every control step boundary k·dt up to `until` (and at sample_times()).
  virtual void on_step(const RunView&) {}
  /// nullopt when the assertion held; otherwise what failed, with times and values
  /// ("count ball-wall = 7, wanted >= 10").
  virtual std::optional<std::string> finish(const RunView&) = 0;
};

/// One parsed `expect` entry. Immutable (a Scene can be copied and run many times).
class Assertion {
 public:
  virtual ~Assertion() = default;
  virtual std::unique_ptr<Check> start(const RunView&) const = 0;
  /// Times (other than control steps) at which the run must stop to sample, e.g. {"at": 2.5}.
  virtual std::vector<double> sample_times() const { return {}; }
};

/// A scene's `expect` list, parsed.
struct Expectations {
  bool present = false;              ///< the file had an `expect` key
  std::optional<double> until;       ///< {"until": T}
  std::vector<sim::Mode> modes;      ///< {"mode": ...}; empty: the caller's choice
  struct Entry {
    std::size_t index = 0;           ///< position in the `expect` list (for messages: expect[2])
    std::string kind;                ///< its kind key
    std::shared_ptr<const Assertion> assertion;
  };
  std::vector<Entry> entries;
};

/// Helpers a kind's parser uses: typed reads that fail as world-file errors at a JSON path (the
/// world files' JsonReader, in `expect`'s wording: "got" shows the value). Throws WorldFileError.
class ExpectParser {
 public:
  ExpectParser(std::string file, const sim::WorldDef& def);

  [[noreturn]] void fail(const std::string& path, const std::string& reason) const { json_.fail(path, reason); }
  /// Rejects keys of `entry` outside `known` (the kind key and x- keys are always allowed).
  void check_keys(const nlohmann::json& entry, const std::string& path, std::string_view kind,
                  std::initializer_list<std::string_view> known) const;
  double number(const nlohmann::json& v, const std::string& path) const { return json_.number(v, path); }
  double non_negative(const nlohmann::json& v, const std::string& path) const { return json_.non_negative(v, path); }
  sim::Vec2 vec2(const nlohmann::json& v, const std::string& path) const { return json_.vec2(v, path); }
  std::string string(const nlohmann::json& v, const std::string& path) const { return json_.string(v, path); }
  bool boolean(const nlohmann::json& v, const std::string& path) const { return json_.boolean(v, path); }
  /// A wall, ball or turtle id that exists in the scene.
  std::string body_id(const nlohmann::json& v, const std::string& path) const;
  /// An id of a turtle.
  std::string turtle_id(const nlohmann::json& v, const std::string& path) const;
  /// "*" (every body; returns empty) or an id or a list of ids of balls or turtles.
  std::vector<std::string> who(const nlohmann::json& v, const std::string& path) const;
  /// An event kind name (ball-ball, ..., touch, fault).
  std::string event_kind(const nlohmann::json& v, const std::string& path) const;
  /// "end" (returns nullopt) or a time >= 0.
  std::optional<double> at_time(const nlohmann::json& v, const std::string& path) const;

 private:
  JsonReader json_;
  const sim::WorldDef& def_;
};

/// A kind of assertion: its kind key and its parser. `entry` is the whole JSON object, `path` its
/// JSON pointer (/expect/3).
struct AssertionKind {
  std::string_view key;
  std::string_view summary;
  std::function<std::shared_ptr<const Assertion>(const nlohmann::json& entry, const std::string& path,
                                                 const ExpectParser& parser)>
      parse;
};

/// Every assertion kind, an explicit table (expect_kinds.cpp).
const std::vector<AssertionKind>& assertion_kinds();

/// Parses a world file's `expect` value (at JSON path /expect). Throws WorldFileError naming `file`.
Expectations parse_expect(const nlohmann::json& expect, const std::string& file, const sim::WorldDef& def);

}  // namespace turtlegas::world
