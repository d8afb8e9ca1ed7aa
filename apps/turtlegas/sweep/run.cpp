// SPDX-License-Identifier: MIT
// `turtlegas sweep`: one run, in this process.
#include <algorithm>
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
#include "turtlegas/world/expect3.hpp"
#include "turtlegas/world/file_error.hpp"
#include "turtlegas/world/world_file.hpp"
#include "turtlegas/world/world_file_3d.hpp"

namespace turtlegas::apps::sweep {

turtle::ServerOptions server_options(const SweepOptions& o) {
  turtle::ServerOptions s;
  s.stack_bytes = o.stack_kib * 1024;
  s.program_budget = o.program_budget;
  return s;
}

namespace {

/// What a result line keeps of the observables: all of them, or the summary and the species
/// without their curves.
json observables_of(json o, bool full) {
  if (full) return o;
  json species = json::array();
  for (json& s : o["species"]) {
    s.erase("msd");
    s.erase("vacf");
    species.push_back(s);
  }
  return {{"summary", o["summary"]}, {"species", species}};
}

/// Run k of a sweep of a 3-D world ("dimensions": 3): its stats, observables and expect list as
/// the 3-D run and test give them.
json run_one_3d(const Spec& spec, const json& w, json line, const std::string& label) {
  world::World3File f;
  try {
    f = world::parse_world3(w.dump(), label);
  } catch (const world::WorldFileError& e) {
    throw BadInput(e.what());
  }
  f.def.mode = spec.mode;
  std::optional<sim::World3> world;
  try {
    world.emplace(f.def);
  } catch (const std::invalid_argument& e) {
    throw BadInput(label + ": " + e.what());
  }
  const double e0 = world->energy();
  if (spec.observe) {
    formats::Observer observer(*world, f.def, f.name, *spec.observe, spec.until, f.wall_ids);
    observer.advance_to(spec.until);
    observer.detach();
    line["observables"] = observables_of(observer.result(), spec.observe_full);
  } else {
    world->advance_to(spec.until);
  }
  line["stats"] = {{"dimensions", 3},
                   {"mode", std::string(sim::to_string(f.def.mode))},
                   {"collisions", world->collisions()},
                   {"events", world->events()},
                   {"energy_start", e0},
                   {"energy_end", world->energy()},
                   {"max_overlap", world->sphere_count() <= 4096 ? std::max(world->max_overlap_now(), 0.0) : 0.0}};
  world::Expectations3 expect;
  try {
    expect = world::parse_expect3(w.dump(), label, f);
  } catch (const world::WorldFileError& e) {
    throw BadInput(e.what());
  }
  if (expect.present && expect.until >= 0.0) {
    const world::Expect3Result r = world::run_expect3(f, expect);
    line["expect"] = {{"passed", r.failures.empty()}, {"assertions", r.assertions}, {"failures", r.failures}};
  }
  return line;
}

}  // namespace

/// Runs run k in this process: its result line (without a newline). Deterministic: no wall-clock
/// figures in it.
json run_one(const Spec& spec, std::size_t k, const turtle::Registry& registry, const turtle::ServerOptions& base) {
  const auto [idx, seed] = decompose(spec, k);
  const json overrides = overrides_of(spec, idx);
  json w = spec.world;
  for (const auto& [ptr, value] : overrides.items()) w[json::json_pointer(ptr)] = value;
  w["seed"] = seed;
  const std::string label = spec.world_file + " (sweep run " + std::to_string(k) + ")";
  if (w.contains("dimensions") && w["dimensions"] == 3)
    return run_one_3d(spec, w, {{"run", k}, {"seed", seed}, {"overrides", overrides}}, label);
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
      line["observables"] = observables_of(observer.result(), spec.observe_full);
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
