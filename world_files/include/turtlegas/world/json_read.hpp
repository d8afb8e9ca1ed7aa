// SPDX-License-Identifier: MIT
// The one typed JSON reader of world files: typed reads, JSON-pointer paths (RFC 6901) and key
// checks, each failing as a WorldFileError that names the file, the path and what is wrong. The
// world-file loader, `expect` (ExpectParser) and the `game` key read through it.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/vec2.hpp"
#include "turtlegas/turtle/json_kind.hpp"

namespace turtlegas::world {

/// A JSON-pointer reference token: `~` and `/` escaped as RFC 6901 has it.
std::string json_token(std::string_view key);
/// `path` + "/" + the token of `key`: the JSON pointer of a member.
std::string json_at(const std::string& path, std::string_view key);
/// `path` + "/" + index: the JSON pointer of an array element.
std::string json_at(const std::string& path, std::size_t index);

/// "a string", "an array", ..., "true or false", "null": what a value is, for messages (one
/// wording for the house: turtlegas/turtle/json_kind.hpp).
using turtle::json_kind;

/// The first key of object `obj` that is neither in `known`, nor `also`, nor private (starting
/// with x-); nullptr when there is none (or `obj` is not an object).
const std::string* unknown_key(const nlohmann::json& obj, std::initializer_list<std::string_view> known,
                               std::string_view also = {});

/// Typed reads of one file's JSON. Two wordings are in use, and each reader keeps its own (tests
/// and users' scripts match them): the loader says what a wrong value *is* ("got an array"), while
/// `expect` and the game show the value itself ("got [1, 2]").
class JsonReader {
 public:
  enum class Wording {
    kind,   ///< "expected a number, got a string"; [x, y] of the wrong size: "got an array of 3"
    value,  ///< "expected a number, got \"ten\""; a non-finite number: "expected a finite number"
  };

  JsonReader(std::string file, Wording wording) : file_(std::move(file)), wording_(wording) {}

  const std::string& file() const { return file_; }
  /// Throws WorldFileError(file, path, reason).
  [[noreturn]] void fail(const std::string& path, const std::string& reason) const;
  /// How a wrong value is shown after "got " in this reader's wording.
  std::string got(const nlohmann::json& v) const;

  /// `obj` must be an object: "<what> must be a JSON object ({...}), got ...".
  void expect_object(const nlohmann::json& v, const std::string& path, std::string_view what) const;
  /// `v` must be an array: "<what> must be a JSON array ([...]), got ...".
  void expect_array(const nlohmann::json& v, const std::string& path, std::string_view what) const;
  /// Rejects a key outside `known` (private x- keys aside) at its own path: `unknown key "k" in
  /// <what>; did you mean "c"? (known keys: a, b, c; keys starting with x- are ignored)`, the
  /// suggestion only for a close misspelling and only when `suggest`.
  void check_keys(const nlohmann::json& obj, const std::string& path, std::string_view what,
                  std::initializer_list<std::string_view> known, bool suggest = true) const;

  /// The member `key` of `obj`, or nullptr.
  const nlohmann::json* find(const nlohmann::json& obj, std::string_view key) const;
  /// The member `key` of `obj`; missing: "<what> needs \"key\"" at `path` (the object's).
  const nlohmann::json& require(const nlohmann::json& obj, const std::string& path, std::string_view key,
                                std::string_view what) const;

  /// A finite number.
  double number(const nlohmann::json& v, const std::string& path) const;
  /// A number > 0: "<name> must be > 0 (got -1)".
  double positive(const nlohmann::json& v, const std::string& path, std::string_view name) const;
  /// A number >= 0: "expected a number >= 0, got -1".
  double non_negative(const nlohmann::json& v, const std::string& path) const;
  /// A non-negative integer; 1e6 is accepted as well as 1000000.
  std::uint64_t natural(const nlohmann::json& v, const std::string& path) const;
  bool boolean(const nlohmann::json& v, const std::string& path) const;
  std::string string(const nlohmann::json& v, const std::string& path) const;
  /// [x, y], two finite numbers.
  sim::Vec2 vec2(const nlohmann::json& v, const std::string& path) const;

 private:
  std::string file_;
  Wording wording_;
};

}  // namespace turtlegas::world
