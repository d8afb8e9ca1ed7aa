// SPDX-License-Identifier: MIT
#include "turtlegas/world/tag_tournament.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <memory>
#include <set>
#include <stdexcept>

#include "turtlegas/turtle/tag_game.hpp"

namespace turtlegas::world {

double t_quantile_975(double df) {
  if (!(df >= 1.0)) throw std::invalid_argument("t_quantile_975: degrees of freedom must be >= 1");
  // Exact to the digits shown up to 30 degrees of freedom; beyond, the Cornish-Fisher expansion
  // around the normal quantile, which at 30 agrees with the table to 1e-6 and improves with df.
  static constexpr double table[] = {12.706204736, 4.302652730, 3.182446305, 2.776445105, 2.570581836, 2.446911851,
                                     2.364624252,  2.306004135, 2.262157163, 2.228138852, 2.200985160, 2.178812830,
                                     2.160368656,  2.144786688, 2.131449546, 2.119905299, 2.109815578, 2.100922040,
                                     2.093024054,  2.085963447, 2.079613845, 2.073873068, 2.068657610, 2.063898562,
                                     2.059538553,  2.055529439, 2.051830516, 2.048407142, 2.045229642, 2.042272456};
  const double n = std::floor(df);
  if (n <= 30.0) return table[static_cast<std::size_t>(n) - 1];
  const double z = 1.959963984540054, z2 = z * z;
  const double g1 = (z2 + 1.0) * z / 4.0;
  const double g2 = ((5.0 * z2 + 16.0) * z2 + 3.0) * z / 96.0;
  const double g3 = (((3.0 * z2 + 19.0) * z2 + 17.0) * z2 - 15.0) * z / 384.0;
  const double g4 = ((((79.0 * z2 + 776.0) * z2 + 1482.0) * z2 - 1920.0) * z2 - 945.0) * z / 92160.0;
  return z + (g1 + (g2 + (g3 + g4 / n) / n) / n) / n;
}

namespace {

/// Mean and 95 % t-interval of per-round values.
Estimate estimate(const std::vector<double>& x) {
  Estimate e;
  e.n = x.size();
  if (x.empty()) return e;
  double sum = 0.0;
  for (double v : x) sum += v;
  e.mean = sum / static_cast<double>(x.size());
  if (x.size() < 2) {
    e.half_width = std::numeric_limits<double>::infinity();
    return e;
  }
  double ss = 0.0;  // two passes: no cancellation in the variance
  for (double v : x) ss += (v - e.mean) * (v - e.mean);
  e.sd = std::sqrt(ss / static_cast<double>(x.size() - 1));
  e.half_width = t_quantile_975(static_cast<double>(x.size() - 1)) * e.sd / std::sqrt(static_cast<double>(x.size()));
  return e;
}

/// a - b over their own rounds, with Welch's interval (unequal variances, Welch-Satterthwaite degrees
/// of freedom): the fallback for two controllers that met in fewer than two rounds.
Estimate welch_difference(const Estimate& a, const Estimate& b) {
  Estimate d;
  d.mean = a.mean - b.mean;
  d.n = std::min(a.n, b.n);
  if (a.n < 2 || b.n < 2) {
    d.half_width = std::numeric_limits<double>::infinity();
    return d;
  }
  const double va = a.sd * a.sd / static_cast<double>(a.n);
  const double vb = b.sd * b.sd / static_cast<double>(b.n);
  d.sd = std::sqrt(va + vb);
  if (d.sd == 0.0) {
    d.half_width = 0.0;
    return d;
  }
  const double df = (va + vb) * (va + vb) /
                    (va * va / static_cast<double>(a.n - 1) + vb * vb / static_cast<double>(b.n - 1));
  d.half_width = t_quantile_975(std::max(1.0, df)) * d.sd;
  return d;
}

std::string number(double v, int digits = 3) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

}  // namespace

Estimate paired_difference(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) throw std::invalid_argument("paired_difference: the two series differ in length");
  std::vector<double> d;
  for (std::size_t r = 0; r < a.size(); ++r)
    if (!std::isnan(a[r]) && !std::isnan(b[r])) d.push_back(a[r] - b[r]);
  return estimate(d);
}

Comparison compare(const std::string& a, const std::vector<double>& a_rounds, const std::string& b,
                   const std::vector<double>& b_rounds) {
  Comparison c;
  c.a = a;
  c.b = b;
  c.difference = paired_difference(a_rounds, b_rounds);
  if (c.difference.n < 2) {
    auto own = [](const std::vector<double>& x) {
      std::vector<double> v;
      for (double t : x)
        if (!std::isnan(t)) v.push_back(t);
      return estimate(v);
    };
    c.difference = welch_difference(own(a_rounds), own(b_rounds));
    c.paired = false;
  }
  c.significant = std::abs(c.difference.mean) > c.difference.half_width;
  return c;
}

TournamentResult run_tag_tournament(const Scene& scene, const std::string& world_file,
                                    const TournamentOptions& options, const turtle::Registry& registry) {
  const std::vector<std::string>& names = options.controllers;
  const std::size_t c = names.size();
  if (c == 0) throw std::invalid_argument("--controllers: name at least one controller");
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
  std::vector<TournamentRow> rows(c);
  std::vector<double> time_it(c, 0.0);
  for (std::size_t k = 0; k < c; ++k) rows[k].controller = names[k];
  for (const auto& [name, p] : options.params) {
    if (!seen.count(name))
      throw std::invalid_argument("--params " + name + ".*: '" + name + "' is not one of --controllers");
    if (!p.is_object()) throw std::invalid_argument("--params " + name + ": params must be a JSON object");
  }
  std::vector<std::vector<double>> round_time_it(c), round_tags(c);
  // The same values by round number, NaN where the controller did not play: rounds pair them.
  const double absent = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::vector<double>> by_round(c, std::vector<double>(options.rounds, absent));

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
      if (auto it = options.params.find(names[slot[i]]); it != options.params.end()) {
        if (!programs[i].params.is_object()) programs[i].params = nlohmann::json::object();
        for (const auto& [key, value] : it->second.items()) programs[i].params[key] = value;
      }
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
    if (!options.play) server.run_until(options.until);
    else if (!options.play(server, r)) break;  // stopped: the rounds so far are the tournament
    round.score = tag->tally(server.time());

    // Per controller, this round's values: its turtles' mean (a round is one sample).
    std::vector<double> t_sum(c, 0.0), tags_sum(c, 0.0);
    std::vector<std::size_t> drove(c, 0);
    for (std::size_t i = 0; i < n_turtles; ++i) {
      TournamentRow& row = rows[slot[i]];
      ++row.turtle_rounds;
      ++drove[slot[i]];
      t_sum[slot[i]] += round.score.time_it[i];
      tags_sum[slot[i]] += static_cast<double>(round.score.tags[i]);
      time_it[slot[i]] += round.score.time_it[i];
      row.tags += round.score.tags[i];
      row.starts_it += i == first_it ? 1 : 0;
      row.faults += server.turtle(i).fault.empty() ? 0 : 1;
    }
    for (std::size_t k = 0; k < c; ++k) {
      if (drove[k] == 0) continue;
      ++rows[k].rounds;
      round_time_it[k].push_back(t_sum[k] / static_cast<double>(drove[k]));
      by_round[k][r] = round_time_it[k].back();
      round_tags[k].push_back(tags_sum[k] / static_cast<double>(drove[k]));
    }
    result.rounds.push_back(std::move(round));
  }

  for (std::size_t k = 0; k < c; ++k) {
    TournamentRow& row = rows[k];
    row.time_it = estimate(round_time_it[k]);
    row.tags_made = estimate(round_tags[k]);
    row.mean_time_it = row.time_it.mean;
    row.tags_per_round = row.tags_made.mean;
  }
  // Less time as "it" is better; then more tags; then the order given (a stable sort).
  std::stable_sort(rows.begin(), rows.end(), [](const TournamentRow& a, const TournamentRow& b) {
    if (a.rounds == 0 || b.rounds == 0) return a.rounds > b.rounds;
    if (a.mean_time_it != b.mean_time_it) return a.mean_time_it < b.mean_time_it;
    return a.tags_per_round > b.tags_per_round;
  });
  for (std::size_t k = 0; k < rows.size(); ++k) rows[k].rank = k + 1;
  auto rounds_of = [&](const TournamentRow& row) -> const std::vector<double>& {
    return by_round[static_cast<std::size_t>(std::find(names.begin(), names.end(), row.controller) - names.begin())];
  };
  auto compare_rows = [&](const TournamentRow& a, const TournamentRow& b) {
    return compare(a.controller, rounds_of(a), b.controller, rounds_of(b));
  };
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = i + 1; j < rows.size(); ++j) result.pairwise.push_back(compare_rows(rows[i], rows[j]));
  const std::size_t played = result.rounds.size();
  if (played % c != 0) {
    std::string starts;
    for (const TournamentRow& row : rows)
      starts += (starts.empty() ? "" : ", ") + row.controller + " " + std::to_string(row.starts_it);
    result.notes.push_back(std::to_string(played) + " rounds do not divide among " + std::to_string(c) +
                           " controllers, so they do not start as \"it\" equally often (" + starts +
                           "); play a multiple of " + std::to_string(c) + " rounds");
  }
  for (std::size_t i = 0; i + 1 < rows.size(); ++i) {
    const Comparison cmp = compare_rows(rows[i], rows[i + 1]);
    if (cmp.significant) continue;
    std::string note = "ranks " + std::to_string(i + 1) + " and " + std::to_string(i + 2) + " (" + rows[i].controller +
                       ", " + rows[i + 1].controller + ") cannot be told apart at 95 %: their mean time as \"it\" ";
    const double d = std::abs(cmp.difference.mean), hw = cmp.difference.half_width;
    if (!std::isfinite(hw)) {
      note += "needs at least 2 rounds each";
    } else {
      note += "differs by " + number(d) + " +/- " + number(hw) + " s (" +
              (cmp.paired ? "paired t-interval over the rounds both played" : "Welch t-interval: they never met twice") +
              ")";
      if (d > 0.0) {
        // The interval narrows as 1/sqrt(rounds): this many would make a difference this size stand out.
        const double need = std::ceil(static_cast<double>(played) * (hw / d) * (hw / d) /
                                      static_cast<double>(c)) * static_cast<double>(c);
        note += "; a difference this size would need about " + number(need, 0) + " rounds";
      }
    }
    result.notes.push_back(note);
  }
  result.ranking = std::move(rows);
  return result;
}

namespace {
nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }
}  // namespace

nlohmann::json to_json(const TournamentResult& result) {
  nlohmann::json ranking = nlohmann::json::array();
  for (const TournamentRow& row : result.ranking)
    ranking.push_back({{"rank", row.rank},
                       {"controller", row.controller},
                       {"rounds", row.rounds},
                       {"turtle_rounds", row.turtle_rounds},
                       {"mean_time_it", row.mean_time_it},
                       {"time_it_ci95", finite_or_null(row.time_it.half_width)},
                       {"tags", row.tags},
                       {"tags_per_round", row.tags_per_round},
                       {"tags_per_round_ci95", finite_or_null(row.tags_made.half_width)},
                       {"starts_it", row.starts_it},
                       {"faults", row.faults}});
  nlohmann::json pairwise = nlohmann::json::array();
  for (const Comparison& p : result.pairwise)
    pairwise.push_back({{"a", p.a},
                        {"b", p.b},
                        {"time_it_difference", p.difference.mean},
                        {"ci95", finite_or_null(p.difference.half_width)},
                        {"significant", p.significant},
                        {"method", p.paired ? "paired" : "welch"}});
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
  nlohmann::json j = {{"format", "turtlegas-tag-tournament/1"},
          {"world", result.world},
          {"rounds", result.options.rounds},
          {"until", result.options.until},
          {"controllers", result.options.controllers},
          {"method", "per controller, one value per round it played (its turtles' mean); 95 % Student t-interval "
                     "over rounds; pairs: paired t-interval of the per-round difference of time as it over the rounds "
                     "both played (Welch's interval over their own rounds for a pair that met in fewer than 2)"},
          {"ranking", ranking},
          {"pairwise", pairwise},
          {"notes", result.notes},
          {"round_results", rounds}};
  if (!result.stopped.empty()) {  // a tournament cut short: what it played
    j["stopped"] = result.stopped;
    j["rounds_played"] = result.rounds.size();
  }
  return j;
}

std::string ranking_table(const TournamentResult& result) {
  std::size_t width = 10;
  for (const TournamentRow& row : result.ranking) width = std::max(width, row.controller.size());
  const int w = static_cast<int>(width);
  auto pm = [](double hw, int digits) { return std::isfinite(hw) ? number(hw, digits) : std::string("inf"); };
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-4s  %-*s  %6s  %9s  %11s  %8s  %6s  %10s  %7s  %6s\n", "rank", w, "controller",
                "rounds", "starts it", "mean it (s)", "+/- 95%", "tags", "tags/round", "+/- 95%", "faults");
  out += line;
  for (const TournamentRow& row : result.ranking) {
    std::snprintf(line, sizeof line, "%-4zu  %-*s  %6zu  %9zu  %11.3f  %8s  %6zu  %10.3f  %7s  %6zu\n", row.rank, w,
                  row.controller.c_str(), row.rounds, row.starts_it, row.mean_time_it,
                  pm(row.time_it.half_width, 3).c_str(), row.tags, row.tags_per_round,
                  pm(row.tags_made.half_width, 3).c_str(), row.faults);
    out += line;
  }
  if (result.ranking.size() > 1) {
    out += "\nmean time as \"it\", row minus column, s (95 % paired t-interval over rounds; * : significant)\n";
    std::snprintf(line, sizeof line, "%-*s", w, "");
    out += line;
    for (std::size_t j = 1; j < result.ranking.size(); ++j) {
      std::snprintf(line, sizeof line, "  %22s", result.ranking[j].controller.c_str());
      out += line;
    }
    out += "\n";
    for (std::size_t i = 0; i + 1 < result.ranking.size(); ++i) {
      std::snprintf(line, sizeof line, "%-*s", w, result.ranking[i].controller.c_str());
      out += line;
      for (std::size_t j = 1; j < result.ranking.size(); ++j) {
        std::string cell;
        if (j > i) {
          for (const Comparison& p : result.pairwise)
            if (p.a == result.ranking[i].controller && p.b == result.ranking[j].controller)
              cell = number(p.difference.mean, 2) + " +/- " + pm(p.difference.half_width, 2) + (p.significant ? " *" : "  ");
        }
        std::snprintf(line, sizeof line, "  %22s", cell.c_str());
        out += line;
      }
      out += "\n";
    }
  }
  for (const std::string& n : result.notes) out += "note: " + n + "\n";
  return out;
}

}  // namespace turtlegas::world
