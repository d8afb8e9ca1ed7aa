// SPDX-License-Identifier: MIT
// Tag tournaments: controllers play a tag world over many seeded rounds (`turtlegas tag`).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
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
  /// Per controller, params that every turtle running it gets on top of its own (--params
  /// name.key=value); a key here replaces the world file's.
  std::map<std::string, nlohmann::json> params;
  /// Plays round `round` on `server` to `until` (unset: server.run_until(until)); false stops the
  /// tournament there, that round not counted (the CLI's limits and Ctrl-C: the rounds played
  /// are ranked and written).
  std::function<bool(turtle::WorldServer& server, std::size_t round)> play;
};

/// A mean over rounds with its 95 % confidence interval: Student's t-interval over the per-round
/// values (mean ± t(0.975, n - 1) s / sqrt(n)); half_width is infinite with fewer than 2 rounds.
struct Estimate {
  double mean = 0.0;
  double half_width = 0.0;  ///< of the 95 % interval
  double sd = 0.0;          ///< sample standard deviation of the per-round values
  std::size_t n = 0;        ///< rounds
};

/// One controller's results over the tournament.
struct TournamentRow {
  std::string controller;
  std::size_t rounds = 0;        ///< rounds this controller played (drove at least one turtle)
  std::size_t turtle_rounds = 0; ///< turtle-rounds (a controller may drive several turtles a round)
  Estimate time_it;              ///< seconds as "it" per round (its turtles' mean in each round)
  Estimate tags_made;            ///< tags made per round (its turtles' mean in each round)
  double mean_time_it = 0.0;     ///< time_it.mean
  std::size_t tags = 0;          ///< tags made, in all
  double tags_per_round = 0.0;   ///< tags_made.mean
  std::size_t starts_it = 0;     ///< rounds it started as "it"
  std::size_t faults = 0;        ///< turtle-rounds whose program failed
  std::size_t rank = 0;          ///< 1 is best: least mean time as "it", then most tags per round
};

/// Two controllers compared: the mean per-round difference of their time as "it" (a - b) over the
/// rounds both played, with a 95 % paired t-interval. Pairing matters: in one tag round the times
/// as "it" share the round's length, so they are negatively correlated and an interval that treats
/// them as independent (Welch's) is too narrow and calls differences significant too often. A pair
/// that met in fewer than 2 rounds falls back to Welch's interval over their own rounds.
struct Comparison {
  std::string a, b;
  Estimate difference;
  bool significant = false;  ///< the interval excludes 0
  bool paired = true;        ///< false: Welch's fallback
};

/// Mean and 95 % t-interval of a[r] - b[r] over the rounds r where neither is NaN (a NaN marks a
/// round the controller did not play); n is that count. Throws std::invalid_argument when the
/// lengths differ.
Estimate paired_difference(const std::vector<double>& a, const std::vector<double>& b);

/// The comparison of two controllers from their per-round values (NaN where one did not play).
Comparison compare(const std::string& a, const std::vector<double>& a_rounds, const std::string& b,
                   const std::vector<double>& b_rounds);
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
  std::vector<Comparison> pairwise;    ///< every pair of the ranking, (i, j) for i < j in rank order
  std::vector<std::string> notes;      ///< ranks that cannot be told apart, unbalanced starts
  /// Why the tournament stopped before its last round (the caller's word, for the JSON's
  /// "stopped"), or empty; rounds.size() rounds were played.
  std::string stopped;
};

/// The 0.975 quantile of Student's t with `df` degrees of freedom (df >= 1; fractional df, for
/// Welch, are rounded down, which widens the interval).
double t_quantile_975(double df);

/// Plays the tournament on a scene that has a tag game (or gets the default one: the first turtle
/// starts as "it", no_tag_back 2 s). Round r (from 0, N turtles, C controllers):
///   - turtle i runs controllers[(i + r) mod C], with the world's params when the world gives that
///     turtle the same controller, {} otherwise;
///   - turtle (r div C) mod N starts as "it", so every controller starts as "it" in turn, once in
///     every C rounds (a note says so when C does not divide the rounds);
///   - a controller's params are the world's (when it gives that turtle the same controller) or
///     {}, with options.params[controller] on top;
///   - the world's seed is seed + r (the turtles' random streams differ per round).
/// Deterministic: the same scene and options give the same result. Throws std::invalid_argument
/// for bad options (an unregistered controller names the known ones).
TournamentResult run_tag_tournament(const Scene& scene, const std::string& world_file,
                                    const TournamentOptions& options, const turtle::Registry& registry);

/// {"world", "rounds", "until", "controllers", "method", "ranking": [{"rank", "controller", "rounds",
/// "turtle_rounds", "mean_time_it", "time_it_ci95", "tags", "tags_per_round", "tags_per_round_ci95",
/// "starts_it", "faults"}], "pairwise": [{"a", "b", "time_it_difference", "ci95", "significant",
/// "method": "paired" | "welch"}],
/// "notes": [...], "round_results": [...]}
nlohmann::json to_json(const TournamentResult& result);

/// The ranking as a fixed-width text table, one row per controller, with a header line; then the
/// pairwise table and the notes.
std::string ranking_table(const TournamentResult& result);

}  // namespace turtlegas::world
