// SPDX-License-Identifier: MIT
// The world file's `game` key, worlds/tag.json and tag tournaments.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/turtle/tag_game.hpp"
#include "turtlegas/world/game_file.hpp"
#include "turtlegas/world/tag_tournament.hpp"
#include "turtlegas/world/world_file.hpp"

namespace tw = turtlegas::world;
namespace tt = turtlegas::turtle;

namespace {

std::string world_with(const std::string& game, int turtles = 2) {
  std::string text = R"({"format": "turtlegas-world/1", "arena": {"width": 200, "height": 200, "boundary": "walls"},
                         "turtles": [)";
  for (int i = 0; i < turtles; ++i)
    text += std::string(i ? ", " : "") + R"({"id": "t)" + std::to_string(i + 1) + R"(", "pos": [)" +
            std::to_string(40 + 50 * i) + ", 100]}";
  return text + "]" + (game.empty() ? "" : ", \"game\": " + game) + "}";
}

std::string error_of(const std::string& text) {
  try {
    tw::parse_scene(text, "w.json", tt::base_registry());
  } catch (const tw::WorldFileError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("the game key", "[world][tag]") {
  const tw::Scene s = tw::parse_scene(world_with(R"({"kind": "tag", "it": "t2", "no_tag_back": 1.5})"), "w.json",
                                      tt::base_registry());
  REQUIRE(s.game);
  CHECK(s.game->it == "t2");
  CHECK(s.game->no_tag_back == 1.5);
  const tw::Scene d = tw::parse_scene(world_with(R"({"kind": "tag"})"), "w.json", tt::base_registry());
  REQUIRE(d.game);
  CHECK(d.game->it == "t1");  // the first turtle by default
  CHECK(d.game->no_tag_back == 2.0);
  CHECK(!tw::parse_scene(world_with(""), "w.json", tt::base_registry()).game);

  CHECK(error_of(world_with(R"({"kind": "tig"})")) ==
        "w.json: /game/kind: unknown game kind \"tig\"; the only kind so far is \"tag\"");
  CHECK(error_of(world_with(R"({"kind": "tag", "it": "t7"})")) ==
        "w.json: /game/it: no turtle has id 't7'; the turtles are: t1, t2");
  CHECK_THAT(error_of(world_with(R"({"kind": "tag", "no_tag_back": -1})")), Catch::StartsWith("w.json: /game/no_tag_back:"));
  CHECK_THAT(error_of(world_with(R"({"kind": "tag", "no_tag_bak": 1})")),
             Catch::StartsWith("w.json: /game/no_tag_bak: unknown key"));
  // A JSON pointer (RFC 6901), as everywhere in world files: `/` and `~` in a key are escaped.
  CHECK(error_of(world_with(R"({"kind": "tag", "a/b~": 1})")) ==
        "w.json: /game/a~1b~0: unknown key \"a/b~\" in game (known keys: kind, it, no_tag_back; keys starting with x- "
        "are ignored)");
  CHECK_THAT(error_of(world_with(R"({"kind": "tag"})", 1)), Catch::Contains("tag needs at least two turtles"));
  CHECK_THAT(error_of(world_with(R"([])")), Catch::StartsWith("w.json: /game: game must be a JSON object"));
}

TEST_CASE("worlds/tag.json plays tag for a minute", "[world][tag]") {
  const tt::Registry registry = turtlegas::controllers::builtin_registry();
  const tw::Scene scene = tw::load_scene("worlds/tag.json", registry);
  REQUIRE(scene.game);
  CHECK(scene.def.turtles.size() >= 4);
  CHECK(scene.def.turtles.size() <= 6);
  auto server = tw::make_server(scene, registry, {});
  std::vector<tt::LogEvent> log;
  server->set_event_log(&log);
  server->run_until(60.0);
  const auto& tag = dynamic_cast<const tt::TagGame&>(*server->game());
  const tt::TagScore score = tag.tally(server->time());
  double total = 0;
  std::size_t tags = 0;
  for (std::size_t i = 0; i < score.ids.size(); ++i) total += score.time_it[i], tags += score.tags[i];
  CHECK(total == Approx(60.0).epsilon(1e-12));
  std::size_t logged = 0, faults = 0;
  for (const auto& e : log) logged += e.kind == "tag", faults += e.kind == "fault";
  CHECK(tags == logged);
  CHECK(tags > 0);
  CHECK(faults == 0);
}

TEST_CASE("a tag tournament is deterministic and reports every field", "[world][tag]") {
  const tt::Registry registry = turtlegas::controllers::builtin_registry();
  const tw::Scene scene = tw::load_scene("worlds/tag.json", registry);
  tw::TournamentOptions options;
  options.controllers = {"tag_chaser", "tag_evader", "tag_random"};
  options.rounds = 6;
  options.until = 20.0;
  const tw::TournamentResult a = tw::run_tag_tournament(scene, "worlds/tag.json", options, registry);
  const tw::TournamentResult b = tw::run_tag_tournament(scene, "worlds/tag.json", options, registry);
  CHECK(tw::to_json(a) == tw::to_json(b));
  CHECK(tw::ranking_table(a) == tw::ranking_table(b));

  const nlohmann::json j = tw::to_json(a);
  for (const char* key : {"format", "world", "rounds", "until", "controllers", "ranking", "round_results"})
    CHECK(j.contains(key));
  REQUIRE(j.at("ranking").size() == 3);
  std::size_t turtle_rounds = 0;
  for (std::size_t k = 0; k < 3; ++k) {
    const auto& row = j.at("ranking")[k];
    for (const char* key : {"rank", "controller", "rounds", "turtle_rounds", "mean_time_it", "time_it_ci95", "tags",
                            "tags_per_round", "tags_per_round_ci95", "starts_it", "faults"})
      CHECK(row.contains(key));
    CHECK(row.at("rank") == k + 1);
    if (k > 0) CHECK(row.at("mean_time_it").get<double>() >= j.at("ranking")[k - 1].at("mean_time_it").get<double>());
    CHECK(row.at("rounds") == 6);  // rounds per controller: 5 turtles, 3 controllers, each plays every round
    turtle_rounds += row.at("turtle_rounds").get<std::size_t>();
  }
  CHECK(turtle_rounds == 6 * scene.def.turtles.size());
  CHECK(j.at("pairwise").size() == 3);
  CHECK(j.contains("method"));
  REQUIRE(j.at("round_results").size() == 6);
  for (std::size_t r = 0; r < 6; ++r) {
    const auto& round = j.at("round_results")[r];
    CHECK(round.at("seed") == scene.def.seed + r);
    double total = 0;
    for (const auto& t : round.at("turtles")) total += t.at("time_it").get<double>();
    CHECK(total == Approx(20.0).epsilon(1e-12));
  }
  // Every controller starts as "it" in turn: rounds 0..2 start with t1 and rotate the controllers.
  CHECK(a.rounds[0].first_it == "t1");
  CHECK(a.rounds[3].first_it == "t2");
  for (const auto& row : a.ranking) CHECK(row.starts_it == 2);

  options.controllers = {"tag_chaser", "nobody"};
  CHECK_THROWS_WITH(tw::run_tag_tournament(scene, "worlds/tag.json", options, registry),
                    Catch::Contains("controller 'nobody' is not registered; known: "));
}

TEST_CASE("t quantiles: the table and the expansion beyond it", "[world][tag]") {
  CHECK(tw::t_quantile_975(1) == Approx(12.706204736).epsilon(1e-9));
  CHECK(tw::t_quantile_975(5) == Approx(2.570581836).epsilon(1e-9));
  CHECK(tw::t_quantile_975(5.7) == tw::t_quantile_975(5));  // fractional df rounded down: wider
  // Beyond the table (reference values from the t distribution's quantile function).
  CHECK(tw::t_quantile_975(31) == Approx(2.039513446).epsilon(2e-7));
  CHECK(tw::t_quantile_975(60) == Approx(2.000297822).epsilon(1e-7));
  CHECK(tw::t_quantile_975(120) == Approx(1.979930405).epsilon(1e-8));
  CHECK(tw::t_quantile_975(1e6) == Approx(1.959966).epsilon(1e-6));
  CHECK_THROWS(tw::t_quantile_975(0.5));
}

TEST_CASE("a tournament's intervals are t-intervals over the rounds each controller played", "[world][tag]") {
  const tt::Registry registry = turtlegas::controllers::builtin_registry();
  const tw::Scene scene = tw::load_scene("worlds/tag.json", registry);
  tw::TournamentOptions options;
  options.controllers = {"tag_chaser", "tag_evader", "tag_random"};
  options.rounds = 12;
  options.until = 20.0;
  const tw::TournamentResult a = tw::run_tag_tournament(scene, "worlds/tag.json", options, registry);
  // Recomputed here from the rounds: per round, the mean over the controller's turtles.
  for (const tw::TournamentRow& row : a.ranking) {
    INFO(row.controller);
    std::vector<double> x;
    for (const auto& r : a.rounds) {
      double sum = 0;
      int n = 0;
      for (std::size_t i = 0; i < r.controllers.size(); ++i)
        if (r.controllers[i] == row.controller) sum += r.score.time_it[i], ++n;
      if (n > 0) x.push_back(sum / n);
    }
    REQUIRE(x.size() == 12);
    CHECK(row.rounds == 12);
    CHECK(row.starts_it == 4);  // 12 rounds, 3 controllers: each starts as "it" 4 times
    double m = 0;
    for (double v : x) m += v;
    m /= 12;
    double ss = 0;
    for (double v : x) ss += (v - m) * (v - m);
    const double hw = 2.200985160 * std::sqrt(ss / 11) / std::sqrt(12.0);  // t(0.975, 11)
    CHECK(row.mean_time_it == Approx(m).epsilon(1e-12));
    CHECK(row.time_it.half_width == Approx(hw).epsilon(1e-9));
  }
  CHECK(a.notes.size() <= 2);
  for (const std::string& n : a.notes) CHECK_THAT(n, Catch::Contains("cannot be told apart at 95 %"));
  // Every pair met in all 12 rounds: the paired interval of the per-round differences.
  auto per_round = [&](const std::string& controller) {
    std::vector<double> x;
    for (const auto& r : a.rounds) {
      double sum = 0;
      int n = 0;
      for (std::size_t i = 0; i < r.controllers.size(); ++i)
        if (r.controllers[i] == controller) sum += r.score.time_it[i], ++n;
      x.push_back(sum / n);
    }
    return x;
  };
  for (const tw::Comparison& c : a.pairwise) {
    INFO(c.a << " - " << c.b);
    CHECK(c.paired);
    const std::vector<double> xa = per_round(c.a), xb = per_round(c.b);
    double m = 0;
    for (std::size_t r = 0; r < 12; ++r) m += xa[r] - xb[r];
    m /= 12;
    double ss = 0;
    for (std::size_t r = 0; r < 12; ++r) ss += (xa[r] - xb[r] - m) * (xa[r] - xb[r] - m);
    CHECK(c.difference.mean == Approx(m).margin(1e-12));
    CHECK(c.difference.half_width == Approx(2.200985160 * std::sqrt(ss / 11) / std::sqrt(12.0)).epsilon(1e-9));
    CHECK(c.difference.n == 12);
    CHECK(c.significant == (std::abs(c.difference.mean) > c.difference.half_width));
    CHECK(c.difference.half_width > 0);
  }

  // Rounds that do not divide among the controllers: a note says the starts are unbalanced.
  options.rounds = 4;
  const tw::TournamentResult b = tw::run_tag_tournament(scene, "worlds/tag.json", options, registry);
  REQUIRE(!b.notes.empty());
  CHECK_THAT(b.notes.front(), Catch::Contains("4 rounds do not divide among 3 controllers"));
  CHECK_THAT(tw::ranking_table(b), Catch::Contains("note: 4 rounds do not divide"));

  // --params: a controller's param on every turtle it drives changes the play; an unknown
  // controller there is an error.
  options.rounds = 3;
  const tw::TournamentResult plain = tw::run_tag_tournament(scene, "worlds/tag.json", options, registry);
  options.params["tag_random"] = {{"leg", 5.0}};
  const tw::TournamentResult short_legs = tw::run_tag_tournament(scene, "worlds/tag.json", options, registry);
  CHECK(tw::to_json(plain).at("round_results") != tw::to_json(short_legs).at("round_results"));
  options.params["wander"] = nlohmann::json::object();
  CHECK_THROWS_WITH(tw::run_tag_tournament(scene, "worlds/tag.json", options, registry),
                    Catch::Contains("--params wander.*: 'wander' is not one of --controllers"));
}

TEST_CASE("pairs of controllers are compared round by round (a paired interval)", "[world][tag]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // By hand: rounds both played give differences 1, 1, 2: mean 4/3, sd sqrt(1/3), t(0.975, 2).
  const tw::Estimate d = tw::paired_difference({1, 2, 3, nan, 5}, {0, 1, 1, 2, nan});
  CHECK(d.n == 3);
  CHECK(d.mean == Approx(4.0 / 3.0).epsilon(1e-15));
  CHECK(d.sd == Approx(std::sqrt(1.0 / 3.0)).epsilon(1e-15));
  CHECK(d.half_width == Approx(4.302652730 * std::sqrt(1.0 / 3.0) / std::sqrt(3.0)).epsilon(1e-9));
  CHECK_THROWS_WITH(tw::paired_difference({1, 2}, {1}), Catch::Contains("differ in length"));

  // Two controllers that never met twice fall back to Welch's interval over their own rounds.
  const tw::Comparison apart = tw::compare("a", {1, nan, 2, nan, 4}, "b", {nan, 3, nan, 5, nan});
  CHECK_FALSE(apart.paired);
  CHECK(apart.difference.mean == Approx(7.0 / 3.0 - 4.0).epsilon(1e-14));

  // Coverage. In tag the round's length is shared, so one controller's time as "it" is the
  // other's complement: a_r + b_r = T. With equal play (true difference 0) a 95 % interval must
  // cover 0 in 95 % of tournaments. Treating the two as independent (Welch, what this code did
  // before) underestimates the variance of the difference by half and covers about 83 %.
  std::mt19937_64 rng(20261202);
  std::normal_distribution<double> noise(0.0, 1.5);
  constexpr int tournaments = 4000, rounds = 20;
  int covered = 0;
  for (int k = 0; k < tournaments; ++k) {
    std::vector<double> a(rounds), b(rounds);
    for (int r = 0; r < rounds; ++r) {
      a[r] = 10.0 + noise(rng);
      b[r] = 20.0 - a[r];
    }
    const tw::Comparison c = tw::compare("a", a, "b", b);
    REQUIRE(c.paired);
    covered += std::abs(c.difference.mean) <= c.difference.half_width ? 1 : 0;
  }
  // Binomial sd of the coverage at 4000 trials: 0.0034; the bounds are 4.4 sd away.
  const double coverage = static_cast<double>(covered) / tournaments;
  INFO("coverage " << coverage);
  CHECK(coverage > 0.935);
  CHECK(coverage < 0.965);
}
