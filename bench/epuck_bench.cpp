// SPDX-License-Identifier: MIT
// An e-puck swarm (issue 34 §6): N e-pucks (radius 3.7, top speed 12.8 units/s, wheels 5.1 apart:
// Enki's EPuck) on a lattice 20 units apart in a square walled arena, each with a ring of infrared
// rays reaching 12 units beyond its rim and running epuck_swarm (controllers/epuck_swarm.cpp): read
// the ring, set the wheels for one control step (dt 0.1 s), every step. bench/enki_ir/enki_epuck.cpp
// is the same scene in Enki; bench/enki_ir.sh runs the two side by side.
// --sense off drives the same loop blind, --sense read reads the ring each step and drives blind
// all the same (read - off: what the reading costs, on the same motion).
// Prints one JSON line: turtle-steps per CPU second of the scheduler thread over the timed steps
// (the first step, which starts every program, is left out), contacts, rays cast.
//
//   epuck_bench [--turtles N] [--steps S] [--rays K] [--sense on|off|read] [--mode exact|step]
#include <chrono>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_common.hpp"
#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/turtle/world_server.hpp"

using namespace turtlegas;
using turtlegas::bench::thread_cpu_seconds;

// Enki's e-puck (enki/robots/e-puck/EPuck.cpp): body radius 3.7, DifferentialWheeled(5.1, 12.8):
// wheels 5.1 apart, 12.8 units/s at most; its infrared sensors reach 12 beyond the body.
constexpr double kRadius = 3.7, kSpeed = 12.8, kAxle = 5.1, kReach = 12.0, kPitch = 20.0, kDt = 0.1;

int run(int argc, char** argv) {
  int turtles = 1000, steps = 300, rays = 8;
  std::string sense = "on";
  sim::Mode mode = sim::Mode::exact;
  const bench::Usage usage("epuck_bench [--turtles N] [--steps S] [--rays K] [--sense on|off|read] [--mode exact|step]");
  const bool go = bench::for_each_option(argc, argv, usage, [&](const std::string& a, const std::string& v) {
    if (a == "--turtles") turtles = static_cast<int>(usage.whole(a, v, 1, 10000000));
    else if (a == "--steps") steps = static_cast<int>(usage.whole(a, v, 1, 100000000));
    else if (a == "--rays") rays = static_cast<int>(usage.whole(a, v, 1, 360));
    else if (a == "--sense") {
      if (v != "on" && v != "off" && v != "read") usage.error("--sense takes on, off or read, not " + v);
      sense = v;
    } else if (a == "--mode") mode = bench::mode_option(usage, v);
    else usage.error("unknown option " + a);
  });
  if (!go) return 0;

  const int side = static_cast<int>(std::ceil(std::sqrt(turtles)));
  sim::WorldDef def;
  def.name = "e-puck swarm";
  def.seed = 1;
  def.dt = kDt;
  def.arena.width = def.arena.height = side * kPitch;
  def.arena.boundary = sim::Boundary::walls;
  std::vector<turtle::TurtleProgram> programs;
  turtle::RangeSensor ring;
  ring.name = "ir";
  ring.range = kRadius + kReach;
  for (int k = 0; k < rays; ++k) ring.bearings.push_back(360.0 * k / rays);
  for (int k = 0; k < turtles; ++k) {
    sim::TurtleDef t;
    t.id = "e" + std::to_string(k);
    t.pos = {kPitch * (k % side + 0.5), kPitch * (k / side + 0.5)};
    t.heading = std::fmod(k * 2.399963, 2 * M_PI);  // golden-angle spread
    t.radius = kRadius;
    t.speed = kSpeed;
    t.turn_rate = 2 * kSpeed / kAxle;  // one wheel forward, one back: wheels() is not limited by it
    def.turtles.push_back(t);
    turtle::TurtleProgram p;
    p.controller = "epuck_swarm";
    p.params = {{"reach", kReach}, {"sense", sense == "on" ? 1.0 : sense == "off" ? 0.0 : 2.0}};
    p.senses = {ring};
    p.axle = kAxle;
    programs.push_back(p);
  }
  turtle::ServerOptions options;
  options.mode = mode;
  options.program_budget = 10.0;
  turtle::WorldServer server(def, programs, controllers::builtin_registry(), options);

  server.run_until(def.dt);  // starts every program: not timed
  // Step by step, timing the steps only: between them, how far each turtle got (the chord of each
  // step's path; enki_epuck measures the same), to show that both swarms drive, not only spin.
  std::vector<sim::Vec2> last(turtles);
  for (int k = 0; k < turtles; ++k) last[k] = server.world().turtle(k).pos;
  double cpu = 0.0, wall = 0.0, moved = 0.0;
  for (int s = 1; s <= steps; ++s) {
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = thread_cpu_seconds();
    server.run_until((s + 1) * def.dt);
    cpu += thread_cpu_seconds() - cpu0;
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (int k = 0; k < turtles; ++k) {
      const sim::Vec2 p = server.world().turtle(k).pos;
      moved += sim::norm(p - last[k]);
      last[k] = p;
    }
  }
  const auto& st = server.world().stats();
  const double turtle_steps = static_cast<double>(turtles) * steps;
  nlohmann::json out = {
      {"bench", "epuck"},
      {"turtles", turtles},
      {"steps", steps},
      {"rays", rays},
      {"sense", sense},
      {"mode", std::string(sim::to_string(mode))},
      {"wall_seconds", wall},
      {"cpu_seconds", cpu},
      {"turtle_steps_per_cpu_second", turtle_steps / cpu},
      {"cpu_ns_per_turtle_step", cpu * 1e9 / turtle_steps},
      {"mean_speed", moved / (turtle_steps * def.dt)},
      {"contacts", st.turtle_wall + st.turtle_wall_end + st.turtle_turtle + st.turtle_ball},
      {"turtle_turtle", st.turtle_turtle},
      {"turtle_wall", st.turtle_wall + st.turtle_wall_end},
      {"contacts_per_turtle_second", (st.turtle_wall + st.turtle_wall_end + st.turtle_turtle + st.turtle_ball) /
                                         (turtles * (steps + 1) * def.dt)},
      {"max_overlap_relative", server.world().measure_overlap().relative},
  };
  std::cout << out.dump() << "\n";
  return 0;
}

int main(int argc, char** argv) { return turtlegas::bench::run_with_exit_codes("epuck_bench", run, argc, argv); }
