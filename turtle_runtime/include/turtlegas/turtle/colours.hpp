// SPDX-License-Identifier: MIT
// Colours for line cameras (Turtle::camera): the world file's "colour" keys, as "#rrggbb".
#pragma once

#include <algorithm>
#include <array>
#include <cctype>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace turtlegas::turtle {

/// The colour names a world file (and a controller's colour param) may use, with their "#rrggbb"
/// (docs/worlds.md, "Colours").
inline constexpr std::array<std::pair<std::string_view, std::string_view>, 13> colour_names = {{
    {"black", "#000000"}, {"white", "#ffffff"}, {"grey", "#808080"}, {"gray", "#808080"}, {"red", "#ff0000"},
    {"green", "#00ff00"}, {"blue", "#0000ff"}, {"yellow", "#ffff00"}, {"cyan", "#00ffff"}, {"magenta", "#ff00ff"},
    {"orange", "#ffa500"}, {"purple", "#800080"}, {"brown", "#8b4513"}}};

/// A colour as cameras read it: "#rrggbb" or one of colour_names (either case), as "#rrggbb" in
/// lower case; nullopt for anything else.
inline std::optional<std::string> parse_colour(std::string_view s) {
  if (s.size() == 7 && s[0] == '#' &&
      std::all_of(s.begin() + 1, s.end(), [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; })) {
    std::string out(s);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
  }
  std::string lower(s);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const auto& [name, hex] : colour_names)
    if (lower == name) return std::string(hex);
  return std::nullopt;
}

/// What cameras see of the bodies (the world file's `"colour"` keys; docs/worlds.md, "Colours"):
/// a colour per body id, and a default per kind for the bodies that have none (gas balls, walls
/// laid by a pen, turtles spawned at run time). Colours are "#rrggbb", lower case.
struct Colours {
  std::map<std::string, std::string, std::less<>> by_id;
  std::string wall = "#808080";    ///< grey
  std::string ball = "#4e79a7";    ///< blue
  std::string turtle = "#59a14f";  ///< green
  /// The colour of body `id` of kind "wall", "wall-end" (its wall's), "ball" or "turtle".
  const std::string& of(std::string_view kind, std::string_view id) const {
    if (const auto it = by_id.find(id); it != by_id.end()) return it->second;
    return kind == "ball" ? ball : kind == "turtle" ? turtle : wall;
  }
};

}  // namespace turtlegas::turtle
