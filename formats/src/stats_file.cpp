// SPDX-License-Identifier: MIT
#include "turtlegas/formats/stats_file.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "turtlegas/sim/mode_names.hpp"

namespace turtlegas::formats {

nlohmann::json energy_rules_json(const RunFigures& run, const sim::World& world) {
  const sim::Stats& st = world.stats();
  // The balls the rules took most from, by the size of what they took: at most kShown of them.
  constexpr std::size_t kShown = 20;
  const std::vector<double>& taken = world.energy_taken();
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < taken.size(); ++i)
    if (taken[i] != 0.0) order.push_back(i);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return std::abs(taken[a]) > std::abs(taken[b]); });
  nlohmann::json bodies = nlohmann::json::array();
  for (std::size_t k = 0; k < std::min(order.size(), kShown); ++k) {
    const std::size_t i = order[k];
    bodies.push_back({{"id", run.ball_name ? run.ball_name(i) : "#" + std::to_string(i)}, {"taken", taken[i]}});
  }
  return {{"wedged", st.energy_wedged}, {"crushed", st.energy_crushed}, {"folded", st.energy_folded},
          {"total", st.energy_rules()}, {"bodies_count", order.size()}, {"bodies", bodies}};
}

nlohmann::json stats_json(const RunFigures& run, const sim::World& world) {
  const sim::Stats& st = world.stats();
  nlohmann::json j = {
      {"world", run.world},
      {"name", run.name},
      {"mode", sim::to_string(run.mode).data()},
      {"until", run.until},
      {"t", run.t},
      {"dt", run.dt},
      {"seed", run.seed},
      {"balls", run.balls},
      {"balls_alive", run.balls_alive},
      {"walls", world.walls().size()},
      {"turtles", run.turtles},
      {"turtles_finished", run.turtles_finished},
      {"cell_size", world.cell_size()},
      {"collisions", st.collisions()},
      {"ball_ball", st.ball_ball},
      {"ball_wall", st.ball_wall},
      {"ball_wall_end", st.ball_wall_end},
      {"exits", st.exits},
      {"wedged", st.wedged},
      {"crushed", st.crushed},
      {"folded", st.folded},
      {"turtle_wall", st.turtle_wall},
      {"turtle_wall_end", st.turtle_wall_end},
      {"turtle_turtle", st.turtle_turtle},
      {"turtle_ball", st.turtle_ball},
      {"touches", run.touches},
      {"faults", run.faults},
      {"cell_crossings", st.cell_crossings},
      {"stale", st.stale},
      {"steps", st.steps},
      {"events", st.events},
      {"wall_seconds", run.wall_seconds},
      {"check_seconds", run.check_seconds},
      {"collisions_per_second", run.collisions_per_second(st)},
      {"energy_start", run.energy_start},
      {"energy_end", run.energy_end},
      {"max_overlap", run.max_overlap},
      {"max_overlap_relative", run.max_overlap_relative},
      {"overlap_samples", run.overlap_samples},
  };
  if (!run.stopped.empty()) j["stopped"] = run.stopped;
  if (!run.resumed.empty()) j["resumed"] = {{"from", run.resumed}, {"t", run.resumed_t}, {"collisions", run.collisions_before}};
  j["energy_rules"] = energy_rules_json(run, world);
  return j;
}

void write_stats(std::ostream& out, const RunFigures& run, const sim::World& world) {
  out << stats_json(run, world).dump(2) << '\n';
}

}  // namespace turtlegas::formats
