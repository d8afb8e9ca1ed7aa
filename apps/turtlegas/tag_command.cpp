// SPDX-License-Identifier: MIT
#include "tag_command.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "output_file.hpp"
#include "cli_common.hpp"
#include "run_loop.hpp"
#include "scene_scales.hpp"
#include "signals.hpp"

#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/world/tag_tournament.hpp"
#include "turtlegas/turtle/json_depth.hpp"

namespace turtlegas::apps {

CLI::App* add_tag_command(CLI::App& app, TagCommandOptions& options) {
  CLI::App* tag = app.add_subcommand("tag", "Play a blindfold-tag tournament between controllers on a world");
  tag->add_option("world", options.world, "World file with two or more turtles (its \"game\" sets the rules)")
      ->required();
  tag->add_option("--controllers", options.controllers, "Comma-separated controller names, e.g. tag_chaser,tag_evader")
      ->required();
  tag->add_option("--rounds", options.rounds, "Rounds to play, each with its own seed")
      ->capture_default_str()
      ->check(integer_in(1, 100000000, "rounds"));
  tag->add_option("--until", options.until, "Simulated seconds per round")
      ->capture_default_str()
      ->check(real_in(0, std::numeric_limits<double>::max(), "seconds", true));
  tag->add_option("--json", options.json_out, "Write the ranking and every round's score here (JSON)");
  tag->add_option("--mode", options.mode, "exact (event-driven) or step (the memo's fixed steps)")
      ->check(CLI::IsMember(sim::mode_names))
      ->capture_default_str();
  tag->add_option("--params", options.params,
                  "A param for every turtle a controller drives, controller.key=value (value: JSON, else a string); "
                  "repeatable");
  add_stack_kib_option(*tag, options.stack_kib);
  add_program_budget_option(*tag, options.program_budget, "the round stops");
  options.limits.add_to(*tag, "the tournament", "the rounds played so far ranked and written");
  return tag;
}

int run_tag_command(const TagCommandOptions& options, const turtle::Registry& registry) {
  const auto start = Clock::now();
  world::TournamentOptions t;
  std::string name;
  for (char ch : options.controllers + ",") {
    if (ch != ',') {
      name += ch;
    } else if (!name.empty()) {
      t.controllers.push_back(name);
      name.clear();
    }
  }
  t.rounds = options.rounds;
  t.until = options.until;
  t.server.mode = sim::mode_from_string(options.mode).value_or(sim::Mode::exact);  // CLI11 checked it
  t.server.stack_bytes = options.stack_kib * 1024;
  t.server.program_budget = options.program_budget;
  for (const std::string& p : options.params) {
    const std::size_t dot = p.find('.'), eq = p.find('=');
    if (dot == std::string::npos || eq == std::string::npos || dot == 0 || eq < dot + 2)
      throw BadInput("--params " + p + ": write controller.key=value, e.g. --params tag_chaser.lunge=30");
    const std::string name = p.substr(0, dot), key = p.substr(dot + 1, eq - dot - 1), text = p.substr(eq + 1);
    if (const auto deep = turtle::json_too_deep(text)) throw BadInput("--params " + p + ": the value is " + *deep);
    nlohmann::json value = nlohmann::json::parse(text, nullptr, false);
    if (value.is_discarded()) value = text;  // a bare word is a string
    t.params[name][key] = value;
  }

  // Opened before the rounds are played, so a bad path costs nothing; renamed into place only
  // when written whole.
  std::optional<OutputFile> json_file;
  check_outputs({{options.json_out, "--json"}}, {{options.world, "the world file"}});
  if (!options.json_out.empty()) json_file.emplace(options.json_out, "--json");
  const world::Scene scene = load(options.world, registry);
  install_stop_signals();  // before the warnings: once they are out, Ctrl-C stops cleanly
  install_crash_report(options.world);
  // Rounds whose scales predict a run that will not finish say so, with numbers, before they
  // start (as run and check do): `tag --until 1e300` otherwise ran for ever without a word.
  SceneScales scales = predict_scales(scene.def, t.server.mode);
  for (const std::string& w : scale_warnings(scales, t.until, "each round to --until " + fmt(t.until)))
    spdlog::warn("{}: {}; lower --until, or --max-wall-seconds or --max-events end it cleanly", options.world, w);

  // Each round in chunks, as `run` runs (run_loop.hpp): a progress line, the limits over the
  // whole tournament, Ctrl-C. A round stopped part way is not counted.
  Limits limits;
  limits.max_wall_seconds = options.limits.wall_seconds();
  limits.max_events = options.limits.events();
  Progress progress(t.until);
  Pace pace;
  std::uint64_t events = 0;  // of the rounds played
  Stopped end{Stop::until, 0};
  std::size_t round_stopped = 0;
  t.play = [&](turtle::WorldServer& server, std::size_t r) {
    stop_inside_steps(server, limits, start, events);
    if (r == 0) pace = first_pace(scales, server.world(), scene.def.dt);
    progress.set_part(t.until, static_cast<double>(r) * t.until, static_cast<double>(t.rounds) * t.until);
    const std::string doing = "round " + std::to_string(r + 1) + " of " + std::to_string(t.rounds) + ": ";
    end = run_server_in_chunks(server, t.until, events, limits, pace, start, progress, doing);
    events += server.world().stats().events;
    round_stopped = r;
    return end.first == Stop::until;
  };
  world::TournamentResult result;
  try {
    result = world::run_tag_tournament(scene, options.world, t, registry);
  } catch (const std::invalid_argument& e) {
    throw BadInput(e.what());
  }
  progress.clear();
  result.stopped = stop_name(end);
  std::printf("%s: %zu rounds of %g s, %zu turtles%s\n", options.world.c_str(), result.rounds.size(), t.until,
              scene.def.turtles.size(),
              result.stopped.empty() ? "" : (" (stopped early: " + result.stopped + ")").c_str());
  std::fputs(world::ranking_table(result).c_str(), stdout);
  for (const std::string& note : result.notes)
    if (note.find("do not divide") != std::string::npos) spdlog::warn("{}", note);
  if (json_file) {
    json_file->stream() << world::to_json(result).dump(2) << '\n';
    json_file->commit();
  }
  if (end.first == Stop::until) return exit_ok;
  spdlog::warn("{}: stopped in round {} of {} ({}); the {} rounds played before it are ranked{}", options.world,
               round_stopped + 1, t.rounds, result.stopped, result.rounds.size(),
               json_file ? " and written to --json " + options.json_out : "");
  return exit_code_for(end);
}

}  // namespace turtlegas::apps
