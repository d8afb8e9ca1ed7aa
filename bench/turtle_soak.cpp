// SPDX-License-Identifier: MIT
// The turtle soak of issue 17 §7: N wandering turtles (1000) in a walled arena with interior walls,
// run for S turtle-steps in all (1e7: 1e4 control steps each), checked every K engine events (1e6)
// and at the end for overlap (more than 1e-9 of a radius), a NaN position or heading, and a turtle
// outside the arena. Not a test (it takes minutes): run it by hand and quote its last line.
//
//   turtle_soak [--turtles N] [--turtle-steps S] [--check-every K] [--mode exact|step]
// Prints one JSON line per check and a summary; exits 1 at the first violation, naming it.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_common.hpp"
#include "turtle_lattice.hpp"
#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/turtle/world_server.hpp"

using namespace turtlegas;

int run(int argc, char** argv) {
  int turtles = 1000;
  double turtle_steps = 1e7;
  double check_every = 1e6;
  sim::Mode mode = sim::Mode::exact;
  const bench::Usage usage("turtle_soak [--turtles N] [--turtle-steps S] [--check-every K] [--mode exact|step]");
  const bool go = bench::for_each_option(argc, argv, usage, [&](const std::string& a, const std::string& v) {
    if (a == "--turtles") turtles = static_cast<int>(usage.whole(a, v, 1, 1000000));
    else if (a == "--turtle-steps") turtle_steps = usage.positive(a, v);
    else if (a == "--check-every") check_every = usage.positive(a, v);
    else if (a == "--mode") mode = bench::mode_option(usage, v);
    else usage.error("unknown option " + a);
  });
  if (!go) return 0;
  // Turtles of radius 5 on a lattice 30 apart, wandering with random turns; three interior bars.
  // (Not a structured binding: the check below captures def, which clang 14 cannot do with one.)
  const bench::TurtleLattice lattice = bench::turtle_lattice(turtles, "turtle soak", 17, "wander");
  const sim::WorldDef& def = lattice.def;
  const std::vector<turtle::TurtleProgram>& programs = lattice.programs;
  const double radius = 5.0, size = def.arena.width;
  turtle::ServerOptions options;
  options.mode = mode;
  options.program_budget = 10.0;
  turtle::WorldServer server(def, programs, controllers::builtin_registry(), options);

  const double steps = turtle_steps / turtles;
  const auto t0 = std::chrono::steady_clock::now();
  double worst_overlap = 0.0;
  std::uint64_t checks = 0, next_check = static_cast<std::uint64_t>(check_every);
  // Advance a control step at a time; check whenever the engine has passed another check_every
  // events (and at the end).
  auto check = [&](double t) {
    ++checks;
    const sim::World& w = server.world();
    const sim::Overlap o = w.measure_overlap();
    worst_overlap = std::max(worst_overlap, o.relative);
    std::string bad;
    for (std::size_t i = 0; i < w.turtle_count() && bad.empty(); ++i) {
      const sim::TurtleState s = w.turtle(i);
      if (!std::isfinite(s.pos.x) || !std::isfinite(s.pos.y) || !std::isfinite(s.heading))
        bad = "turtle " + def.turtles[i].id + " has a NaN or infinite position or heading";
      else if (s.pos.x < radius * (1 - 1e-9) || s.pos.y < radius * (1 - 1e-9) || s.pos.x > size - radius * (1 - 1e-9) ||
               s.pos.y > size - radius * (1 - 1e-9))
        bad = "turtle " + def.turtles[i].id + " escaped the arena";
    }
    if (bad.empty() && o.relative > 1e-9) bad = "overlap of " + std::to_string(o.relative) + " of a radius";
    const nlohmann::json line = {{"t", t},
                                 {"events", w.stats().events},
                                 {"contacts", w.stats().turtle_wall + w.stats().turtle_wall_end + w.stats().turtle_turtle},
                                 {"max_overlap_relative", o.relative},
                                 {"wall_seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()},
                                 {"violation", bad}};
    std::cout << line.dump() << std::endl;
    return bad.empty();
  };
  bool ok = true;
  for (std::uint64_t k = 1; ok && static_cast<double>(k) <= steps; ++k) {
    const double t = static_cast<double>(k) * def.dt;
    server.run_until(t);
    if (server.world().stats().events >= next_check) {
      ok = check(t);
      while (next_check <= server.world().stats().events) next_check += static_cast<std::uint64_t>(check_every);
    }
  }
  if (ok) ok = check(server.time());
  std::size_t faults = 0;
  for (std::size_t i = 0; i < server.turtle_count(); ++i) faults += server.turtle(i).fault.empty() ? 0 : 1;
  const nlohmann::json summary = {
      {"soak", "turtles"},
      {"mode", std::string(sim::to_string(mode))},
      {"turtles", turtles},
      {"turtle_steps", static_cast<double>(turtles) * std::floor(steps)},
      {"t", server.time()},
      {"events", server.world().stats().events},
      {"checks", checks},
      {"worst_overlap_relative", worst_overlap},
      {"faults", faults},
      {"wall_seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()},
      {"ok", ok && faults == 0},
  };
  std::cout << summary.dump() << "\n";
  return ok && faults == 0 ? 0 : 1;
}

int main(int argc, char** argv) { return turtlegas::bench::run_with_exit_codes("turtle_soak", run, argc, argv); }
