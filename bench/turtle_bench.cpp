// SPDX-License-Identifier: MIT
// Turtles at scale: N turtles, each running its own coroutine program, in an arena with walls.
// Prints one JSON line: turtle-steps per second (wall clock, and the scheduler thread's CPU time per
// turtle-step, which a busy shared machine disturbs less), the cost of a coroutine switch, memory per turtle.
//
//   turtle_bench [--turtles N] [--steps S] [--controller NAME] [--mode exact|step] [--stack-kib K]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>

#include <nlohmann/json.hpp>

#include "bench_common.hpp"
#include "fiber.hpp"
#include "turtle_lattice.hpp"
#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/turtle/world_server.hpp"

using namespace turtlegas;
using turtlegas::bench::thread_cpu_seconds;

namespace {

// Resident and peak resident set size, bytes (from /proc/self/status).
long status_kib(const std::string& key) {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind(key + ":", 0) == 0) return std::strtol(line.c_str() + key.size() + 1, nullptr, 10);
  return -1;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Coroutine switch cost: one fiber that suspends forever; each resume() is two switches.
double switch_ns(std::size_t stack_bytes) {
  using turtle::detail::Fiber;
  Fiber* self = nullptr;
  Fiber f(
      [&] {
        for (;;) self->suspend();
      },
      stack_bytes);
  self = &f;
  const int n = 2'000'000;
  f.resume(0);
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < n; ++k) f.resume(0);
  return seconds_since(t0) * 1e9 / (2.0 * n);
}

}  // namespace

int run(int argc, char** argv) {
  int turtles = 10000;
  int steps = 300;
  std::string controller = "wander";
  sim::Mode mode = sim::Mode::exact;
  std::size_t stack_kib = 32;
  const bench::Usage usage("turtle_bench [--turtles N] [--steps S] [--controller NAME] [--mode exact|step] [--stack-kib K]");
  const bool go = bench::for_each_option(argc, argv, usage, [&](const std::string& a, const std::string& v) {
    if (a == "--turtles") turtles = static_cast<int>(usage.whole(a, v, 1, 10000000));
    else if (a == "--steps") steps = static_cast<int>(usage.whole(a, v, 1, 100000000));
    else if (a == "--controller") controller = v;
    else if (a == "--mode") mode = bench::mode_option(usage, v);
    else if (a == "--stack-kib") stack_kib = static_cast<std::size_t>(usage.whole(a, v, 16, 1048576));
    else usage.error("unknown option " + a);
  });
  if (!go) return 0;
  const long rss0 = status_kib("VmRSS");

  const auto [def, programs] = bench::turtle_lattice(turtles, "turtle bench", 1, controller);
  turtle::ServerOptions options;
  options.mode = mode;
  options.stack_bytes = stack_kib * 1024;
  options.program_budget = 10.0;
  turtle::WorldServer server(def, programs, controllers::builtin_registry(), options);

  // The first control step starts every program (a fiber and its stack each): timed apart.
  const auto t_start = std::chrono::steady_clock::now();
  server.run_until(def.dt);
  const double start_seconds = seconds_since(t_start);
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = thread_cpu_seconds();
  server.run_until((steps + 1) * def.dt);
  const double cpu = thread_cpu_seconds() - cpu0;
  const double wall = seconds_since(t0);
  const long rss1 = status_kib("VmRSS");
  const long hwm = status_kib("VmHWM");

  const auto& st = server.world().stats();
  const double turtle_steps = static_cast<double>(turtles) * steps;
  nlohmann::json out = {
      {"bench", "turtles"},
      {"turtles", turtles},
      {"steps", steps},
      {"controller", controller},
      {"mode", std::string(sim::to_string(mode))},
      {"wall_seconds", wall},
      {"start_seconds", start_seconds},
      {"turtle_steps_per_second", turtle_steps / wall},
      {"ns_per_turtle_step", wall * 1e9 / turtle_steps},
      {"cpu_seconds", cpu},
      {"cpu_ns_per_turtle_step", cpu * 1e9 / turtle_steps},
      {"contacts", st.turtle_wall + st.turtle_wall_end + st.turtle_turtle + st.turtle_ball},
      {"events", st.events},
      {"stack_reserved_bytes", server.stack_reservation()},
      {"rss_bytes_per_turtle", (rss1 - rss0) * 1024.0 / turtles},
      {"peak_rss_bytes_per_turtle", (hwm - rss0) * 1024.0 / turtles},
      {"switch_ns", switch_ns(options.stack_bytes)},
      {"max_overlap_relative", server.world().measure_overlap().relative},
  };
  std::cout << out.dump() << "\n";
  return 0;
}

int main(int argc, char** argv) { return turtlegas::bench::run_with_exit_codes("turtle_bench", run, argc, argv); }
