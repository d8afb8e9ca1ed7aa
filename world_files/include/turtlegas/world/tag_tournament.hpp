// SPDX-License-Identifier: MIT
// Tag tournaments: controllers play a tag world over many seeded rounds (`turtlegas tag`).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/turtle/world_server.hpp"
#include "turtlegas/world/scene.hpp"

namespace turtlegas::world {

struct TournamentOptions {
  std::vector<std::string> controllers;  ///< registered names, at least one, no repeats
  std::size_t rounds = 20;               ///< at least 1
  double until = 60.0;                   ///< seconds of play per round, > 0
  turtle::ServerOptions server;          ///< mode, stack size, program budget
};

/// One controller's results over the tournament.
struct TournamentRow {
  std::string controller;
  std::size_t rounds = 0;        ///< turtle-rounds played (a controller may drive several turtles a round)
  double mean_time_it = 0.0;     ///< seconds as "it" per turtle-round
  std::size_t tags = 0;          ///< tags made, in all
  double tags_per_round = 0.0;   ///< tags made per turtle-round
  std::size_t starts_it = 0;     ///< turtle-rounds it started as "it"
  std::size_t faults = 0;        ///< turtle-rounds whose program failed
  std::size_t rank = 0;          ///< 1 is best: least mean time as "it", then most tags per round
};

struct TournamentRound {
  std::size_t round = 0;
  std::uint64_t seed = 0;
  std::string first_it;                  ///< turtle id
  std::vector<std::string> controllers;  ///< per turtle, world-file order
  turtle::TagScore score;                ///< at the round's end
};

struct TournamentResult {
  std::string world;  ///< the file, as given
  TournamentOptions options;
  std::vector<TournamentRound> rounds;
  std::vector<TournamentRow> ranking;  ///< best first
};

/// Plays the tournament on a scene that has a tag game (or gets the default one: the first turtle
/// starts as "it", no_tag_back 2 s). Round r (from 0, N turtles, C controllers):
///   - turtle i runs controllers[(i + r) mod C], with the world's params when the world gives that
///     turtle the same controller, {} otherwise;
///   - turtle (r div C) mod N starts as "it", so every controller starts as "it" in turn;
///   - the world's seed is seed + r (the turtles' random streams differ per round).
/// Deterministic: the same scene and options give the same result. Throws std::invalid_argument
/// for bad options (an unregistered controller names the known ones).
TournamentResult run_tag_tournament(const Scene& scene, const std::string& world_file,
                                    const TournamentOptions& options, const turtle::Registry& registry);

/// {"world", "rounds", "until", "controllers", "ranking": [{"rank", "controller", "rounds",
/// "mean_time_it", "tags", "tags_per_round", "starts_it", "faults"}], "round_results": [...]}
nlohmann::json to_json(const TournamentResult& result);

/// The ranking as a fixed-width text table, one row per controller, with a header line.
std::string ranking_table(const TournamentResult& result);

}  // namespace turtlegas::world
