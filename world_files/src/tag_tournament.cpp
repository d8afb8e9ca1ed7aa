// SPDX-License-Identifier: MIT
#include "turtlegas/world/tag_tournament.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <set>
#include <stdexcept>

#include "turtlegas/turtle/tag_game.hpp"

namespace turtlegas::world {

TournamentResult run_tag_tournament(const Scene& scene, const std::string& world_file,
                                    const TournamentOptions& options, const turtle::Registry& registry) {
  const std::vector<std::string>& names = options.controllers;
  if (names.empty()) throw std::invalid_argument("--controllers: name at least one controller");
  std::set<std::string> seen;
  for (const std::string& n : names) {
    registry.require(n, "--controllers");
    if (!seen.insert(n).second) throw std::invalid_argument("--controllers: '" + n + "' is named twice");
  }
  if (options.rounds < 1) throw std::invalid_argument("--rounds must be at least 1");
  if (!(options.until > 0.0) || !std::isfinite(options.until))
    throw std::invalid_argument("--until must be a finite time > 0 in seconds");
  const std::size_t n_turtles = scene.def.turtles.size();
  if (n_turtles < 2)
    throw std::invalid_argument(world_file + ": tag needs at least two turtles (the world has " +
                                std::to_string(n_turtles) + ")");
  const turtle::TagRules base = scene.game ? *scene.game : turtle::TagRules{scene.def.turtles.front().id, 2.0};

  TournamentResult result;
  result.world = world_file;
  result.options = options;
  const std::size_t c = names.size();
  std::vector<TournamentRow> rows(c);
  std::vector<double> time_it(c, 0.0);
  for (std::size_t k = 0; k < c; ++k) rows[k].controller = names[k];

  for (std::size_t r = 0; r < options.rounds; ++r) {
    sim::WorldDef def = scene.def;
    def.seed = scene.def.seed + r;
    std::vector<turtle::TurtleProgram> programs = scene.programs;
    std::vector<std::size_t> slot(n_turtles);
    TournamentRound round;
    round.round = r;
    round.seed = def.seed;
    for (std::size_t i = 0; i < n_turtles; ++i) {
      slot[i] = (i + r) % c;
      if (programs[i].controller != names[slot[i]]) programs[i].params = nlohmann::json::object();
      programs[i].controller = names[slot[i]];
      round.controllers.push_back(names[slot[i]]);
    }
    const std::size_t first_it = (r / c) % n_turtles;
    turtle::TagRules rules = base;
    rules.it = def.turtles[first_it].id;
    round.first_it = rules.it;

    turtle::WorldServer server(def, std::move(programs), registry, options.server);
    auto game = std::make_unique<turtle::TagGame>(rules);
    const turtle::TagGame* tag = game.get();
    server.set_game(std::move(game));
    server.run_until(options.until);
    round.score = tag->tally(server.time());

    for (std::size_t i = 0; i < n_turtles; ++i) {
      TournamentRow& row = rows[slot[i]];
      ++row.rounds;
      time_it[slot[i]] += round.score.time_it[i];
      row.tags += round.score.tags[i];
      row.starts_it += i == first_it ? 1 : 0;
      row.faults += server.turtle(i).fault.empty() ? 0 : 1;
    }
    result.rounds.push_back(std::move(round));
  }

  for (std::size_t k = 0; k < c; ++k) {
    TournamentRow& row = rows[k];
    if (row.rounds > 0) {
      row.mean_time_it = time_it[k] / static_cast<double>(row.rounds);
      row.tags_per_round = static_cast<double>(row.tags) / static_cast<double>(row.rounds);
    }
  }
  // Less time as "it" is better; then more tags; then the order given (a stable sort).
  std::stable_sort(rows.begin(), rows.end(), [](const TournamentRow& a, const TournamentRow& b) {
    if (a.rounds == 0 || b.rounds == 0) return a.rounds > b.rounds;
    if (a.mean_time_it != b.mean_time_it) return a.mean_time_it < b.mean_time_it;
    return a.tags_per_round > b.tags_per_round;
  });
  for (std::size_t k = 0; k < rows.size(); ++k) rows[k].rank = k + 1;
  result.ranking = std::move(rows);
  return result;
}

nlohmann::json to_json(const TournamentResult& result) {
  nlohmann::json ranking = nlohmann::json::array();
  for (const TournamentRow& row : result.ranking)
    ranking.push_back({{"rank", row.rank},
                       {"controller", row.controller},
                       {"rounds", row.rounds},
                       {"mean_time_it", row.mean_time_it},
                       {"tags", row.tags},
                       {"tags_per_round", row.tags_per_round},
                       {"starts_it", row.starts_it},
                       {"faults", row.faults}});
  nlohmann::json rounds = nlohmann::json::array();
  for (const TournamentRound& r : result.rounds) {
    nlohmann::json turtles = nlohmann::json::array();
    for (std::size_t i = 0; i < r.score.ids.size(); ++i)
      turtles.push_back({{"id", r.score.ids[i]},
                         {"controller", r.controllers[i]},
                         {"time_it", r.score.time_it[i]},
                         {"tags", r.score.tags[i]},
                         {"tagged", r.score.tagged[i]}});
    rounds.push_back({{"round", r.round}, {"seed", r.seed}, {"first_it", r.first_it}, {"it_at_end", r.score.it},
                      {"turtles", turtles}});
  }
  return {{"format", "turtlegas-tag-tournament/1"},
          {"world", result.world},
          {"rounds", result.options.rounds},
          {"until", result.options.until},
          {"controllers", result.options.controllers},
          {"ranking", ranking},
          {"round_results", rounds}};
}

std::string ranking_table(const TournamentResult& result) {
  std::size_t width = 10;
  for (const TournamentRow& row : result.ranking) width = std::max(width, row.controller.size());
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-4s  %-*s  %6s  %14s  %6s  %10s  %6s\n", "rank", static_cast<int>(width),
                "controller", "rounds", "mean it (s)", "tags", "tags/round", "faults");
  out += line;
  for (const TournamentRow& row : result.ranking) {
    std::snprintf(line, sizeof line, "%-4zu  %-*s  %6zu  %14.3f  %6zu  %10.3f  %6zu\n", row.rank,
                  static_cast<int>(width), row.controller.c_str(), row.rounds, row.mean_time_it, row.tags,
                  row.tags_per_round, row.faults);
    out += line;
  }
  return out;
}

}  // namespace turtlegas::world
