// SPDX-License-Identifier: MIT
#include "turtlegas/formats/stats_file.hpp"

#include "turtlegas/sim/mode_names.hpp"

namespace turtlegas::formats {

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
      {"collisions_per_second", run.collisions_per_second(st)},
      {"energy_start", run.energy_start},
      {"energy_end", run.energy_end},
      {"max_overlap", run.max_overlap},
      {"max_overlap_relative", run.max_overlap_relative},
      {"overlap_samples", run.overlap_samples},
  };
  if (!run.stopped.empty()) j["stopped"] = run.stopped;
  return j;
}

void write_stats(std::ostream& out, const RunFigures& run, const sim::World& world) {
  out << stats_json(run, world).dump(2) << '\n';
}

}  // namespace turtlegas::formats
