// SPDX-License-Identifier: MIT
// `turtlegas sweep`: one run, in this process.
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "run_loop.hpp"
#include "sweep/sweep.hpp"
#include "turtlegas/formats/stats_file.hpp"
#include "turtlegas/world/scenario.hpp"
#include "turtlegas/world/world_file.hpp"

namespace turtlegas::apps::sweep {

turtle::ServerOptions server_options(const SweepOptions& o) {
  turtle::ServerOptions s;
  s.stack_bytes = o.stack_kib * 1024;
  s.program_budget = o.program_budget;
  return s;
}

/// Runs run k in this process: its result line (without a newline). Deterministic: no wall-clock
/// figures in it.
json run_one(const Spec& spec, std::size_t k, const turtle::Registry& registry, const turtle::ServerOptions& base) {
  const auto [idx, seed] = decompose(spec, k);
  const json overrides = overrides_of(spec, idx);
  json w = spec.world;
  for (const auto& [ptr, value] : overrides.items()) w[json::json_pointer(ptr)] = value;
  w["seed"] = seed;
  const std::string label = spec.world_file + " (sweep run " + std::to_string(k) + ")";
  world::Scene scene;
  try {
    scene = world::parse_scene(w.dump(), label, registry);
  } catch (const world::WorldFileError& e) {
    throw BadInput(e.what());
  }
  turtle::ServerOptions options = base;
  options.mode = spec.mode;
  json line = {{"run", k}, {"seed", seed}, {"overrides", overrides}};
  formats::RunFigures run;
  run.world = spec.text["world"].get<std::string>();  // as the spec says: the results do not depend on where it lies
  run.name = scene.def.name;
  run.mode = spec.mode;
  run.until = spec.until;
  run.dt = scene.def.dt;
  run.seed = seed;
  run.balls = scene.def.balls.size();
  run.turtles = scene.def.turtles.size();
  // Exactly one of these runs the scene: the bare engine, or the world server when there are
  // turtles (which then owns the engine).
  std::optional<sim::World> bare;
  std::unique_ptr<turtle::WorldServer> server;
  if (spec.observe && !scene.def.turtles.empty())
    throw BadInput(label + ": the spec's observe measures a gas run by the bare engine, and this run has turtles");
  if (scene.def.turtles.empty()) {
    bare.emplace(make_world(scene.def, spec.mode, label));
    run.energy_start = bare->energy();
    if (spec.observe) {
      formats::Observer observer(*bare, scene.def, *spec.observe, spec.until);
      observer.advance_to(spec.until);
      observer.detach();
      json o = observer.result();
      if (spec.observe_full) {
        line["observables"] = o;
      } else {
        json species = json::array();
        for (json& s : o["species"]) {
          s.erase("msd");
          s.erase("vacf");
          species.push_back(s);
        }
        line["observables"] = {{"summary", o["summary"]}, {"species", species}};
      }
    } else {
      bare->advance_to(spec.until);
    }
  } else {
    server = make_server(scene, registry, options, label);
    std::vector<turtle::LogEvent> events;
    server->set_event_log(&events);
    run.energy_start = server->world().energy();
    server->run_until(spec.until);
    server->set_event_log(nullptr);
    for (const auto& e : events) run.touches += e.kind == "touch", run.faults += e.kind == "fault";
    if (server->game()) line["tag"] = server->game()->score(server->time());
  }
  const sim::World& world = server ? server->world() : *bare;
  finish_run(run, world, server.get());
  json stats = formats::stats_json(run, world);
  // Wall-clock figures differ from run to run of the same input: they stay out of the results.
  stats.erase("wall_seconds");
  stats.erase("collisions_per_second");
  line["stats"] = stats;
  if (scene.expect.present && scene.expect.until) {
    world::ExpectResult r;
    try {
      r = world::run_expectations(scene, registry, spec.mode, options);
    } catch (const std::invalid_argument& e) {
      throw BadInput(label + ": " + e.what());
    }
    line["expect"] = {{"passed", r.passed()}, {"assertions", r.assertions}, {"failures", r.failures}};
  }
  return line;
}
}  // namespace turtlegas::apps::sweep
