// SPDX-License-Identifier: MIT
#include "turtlegas/world/game_file.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>
#include <vector>

#include "turtlegas/sim/suggest.hpp"

namespace turtlegas::world {

turtle::TagRules read_game(const nlohmann::json& game, const sim::WorldDef& def, const JsonReader& reader) {
  auto die = [&](const std::string& path, const std::string& reason) { reader.fail(path, reason); };
  if (!game.is_object()) die("/game", "game must be a JSON object ({\"kind\": \"tag\", \"it\": \"t1\"})");
  reader.check_keys(game, "/game", "game", {"kind", "it", "no_tag_back"}, /*suggest=*/false);
  if (!game.contains("kind")) die("/game", "game needs \"kind\"; the only kind so far is \"tag\"");
  if (!game["kind"].is_string() || game["kind"] != "tag")
    die("/game/kind", "unknown game kind " + game["kind"].dump() + "; the only kind so far is \"tag\"");
  if (def.turtles.size() < 2) die("/game", "tag needs at least two turtles (the world has " +
                                                std::to_string(def.turtles.size()) + ")");
  turtle::TagRules rules;
  rules.it = def.turtles.front().id;
  if (game.contains("it")) {
    const auto& it = game["it"];
    if (!it.is_string()) die("/game/it", "expected a turtle id (a string), got " + it.dump());
    rules.it = it.get<std::string>();
    std::vector<std::string_view> ids;
    for (const auto& t : def.turtles) ids.push_back(t.id);
    if (std::find(ids.begin(), ids.end(), rules.it) == ids.end())
      die("/game/it", "no turtle has id '" + rules.it + "'; the turtles are: " + sim::join_names(ids));
  }
  if (game.contains("no_tag_back")) {
    const auto& v = game["no_tag_back"];
    if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < 0.0)
      die("/game/no_tag_back", "expected a time >= 0 in seconds, got " + v.dump());
    rules.no_tag_back = v.get<double>();
  }
  return rules;
}

}  // namespace turtlegas::world
