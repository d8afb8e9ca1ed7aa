// SPDX-License-Identifier: MIT
// The world-file loader's Reader: one parsed document into a Scene, section by section. Its
// sections are read in world_file.cpp (document, arena, effects, walls, draw, balls, categories),
// world_file_turtles.cpp (turtles, sensors, scripts) and world_file_gas.cpp (gases and their ids).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <nlohmann/json.hpp>

#include "gas.hpp"
#include "turtlegas/sim/format.hpp"
#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/world_server.hpp"
#include "turtlegas/world/json_read.hpp"
#include "turtlegas/world/scene.hpp"

namespace turtlegas::world::detail {

using json = nlohmann::json;
using sim::Vec2;

inline std::string num(double v) { return sim::format_number(v); }
inline std::string vec(Vec2 v) { return sim::format_vec(v); }
inline std::string at(const std::string& path, std::string_view key) { return json_at(path, key); }
inline std::string at(const std::string& path, std::size_t index) { return json_at(path, index); }

/// The category every object is in unless it names others; bit 0, sim::Layers' default.
inline constexpr std::string_view default_category = "default";
/// Bits 0..31 of a category mask: "default" and at most 31 names.
inline constexpr std::size_t max_categories = 32;

/// Reads one parsed document into a Scene, remembering where each ball came from so that a
/// problem found later (by sim::validate) can be reported at its JSON path. Controller names are
/// checked against `registry` when one is given.
class Reader : public JsonReader {
 public:
  Reader(std::string file, const turtle::Registry* registry)
      : JsonReader(std::move(file), Wording::kind), registry_(registry) {}

  Scene read(const json& doc, std::string_view default_name);
  // Also one entry at a time (entries.cpp).
  void read_balls(const json& v, std::vector<sim::BallDef>& balls);
  void read_turtles(const json& v, std::vector<sim::TurtleDef>& turtles, std::vector<turtle::TurtleProgram>& programs);

 private:
  std::string id(const json& obj, const std::string& path, std::string_view what) {
    const std::string p = at(path, "id");
    std::string s = string(require(obj, path, "id", what), p);
    if (s.empty()) fail(p, "id must not be empty");
    auto [it, fresh] = ids_.emplace(s, p);
    if (!fresh) {
      if (it->second.empty())
        fail(p, "id \"" + s + "\" is taken by an arena wall of boundary \"walls\"; choose another id");
      fail(p, "duplicate id \"" + s + "\" (already used at " + it->second +
                  "); every wall, ball and turtle needs its own id");
    }
    return s;
  }

  void read_arena(const json& v, sim::ArenaDef& arena);
  void read_effects(const json& v, sim::EffectsDef& effects);
  void collect_categories(const json& doc);
  void collect_category(const json& obj, const std::string& path);
  sim::Layers layers(const json& obj, const std::string& path) const;
  std::uint32_t category_bits(const json& v, const std::string& path) const;
  void read_walls(const json& v, std::vector<sim::WallDef>& walls);
  void read_draw(const json& v, std::vector<sim::WallDef>& walls);
  std::vector<turtle::SensorArc> read_sensors(const json& v, const std::string& path) const;
  std::vector<turtle::RangeSensor> read_senses(const json& v, const std::string& path) const;
  /// `senses`: the turtle's range sensors, which ["sense", NAME] must name.
  void check_script(const json& params, const std::string& path, const std::vector<turtle::RangeSensor>& senses) const;
  /// A body's optional "colour" (docs/worlds.md, "Colours") into colours_ under its id.
  void read_colour(const json& obj, const std::string& path, const std::string& body_id);
  /// A colour: "#rrggbb" (either case) or a name (colour_names); returned as "#rrggbb", lower case.
  std::string colour(const json& v, const std::string& path) const;
  std::vector<turtle::View> read_views(const json& v, const sim::WorldDef& def);
  std::vector<GasSpec> read_gases(const json& v, const sim::WorldDef& def);
  std::string path_of(const sim::DefProblem& p) const;
  void check_gas_ids(const std::vector<GasSpec>& gases) const;

  const turtle::Registry* registry_;
  std::unordered_map<std::string, std::string> ids_;  // id -> JSON path of its "id" ("" for arena walls)
  std::size_t explicit_balls_ = 0;
  std::vector<std::size_t> gas_first_;  // index in WorldDef::balls of each gas entry's first ball
  std::vector<std::string> wall_paths_;  // JSON path of each of WorldDef::walls (file walls, then drawn)
  turtle::Colours colours_;  // the bodies' "colour" keys
  std::vector<std::string> categories_{std::string(default_category)};  // name of bit k
};

}  // namespace turtlegas::world::detail
