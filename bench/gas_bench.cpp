// SPDX-License-Identifier: MIT
//
// gas_bench: runs one world file in one mode and prints one JSON line of throughput and memory
// figures. One scene per process, so that the peak resident set belongs to that scene alone.
//
//   gas_bench WORLD.json [--mode exact|step] [--collisions K | --sim-seconds T]
//                        [--steps S | --ball-steps B] [--max-wall W]
//
// Exact mode runs until K collisions (default max(5e6, 10 N), so that every ball of the largest
// scenes collides about ten times) or T simulated seconds. It advances in chunks of simulated time
// sized from the collision rate seen so far, so no one has to guess T for a scene. Step mode runs S
// steps (default ceil(B / N) with B = max(1e7, 10 N) ball-steps). --max-wall stops a run early
// (default 300 s), as does a scene that runs out of collisions; the line then says "truncated":
// true. Only advance_to is timed. Exact-mode lines list the simulated time and collision count at
// the end of each chunk ("chunk_ends"; with --sim-seconds ten equal spans, for batch means).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <nlohmann/json.hpp>

#include "bench_common.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/world/world_file.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using turtlegas::bench::thread_cpu_seconds;
namespace sim = turtlegas::sim;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A field of /proc/self/status in bytes (VmRSS, VmHWM), or 0 where there is no /proc.
std::uint64_t proc_status_bytes(std::string_view field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.size() > field.size() && line.compare(0, field.size(), field) == 0 && line[field.size()] == ':') {
      return std::stoull(line.substr(field.size() + 1)) * 1024;  // the kernel reports kB
    }
  }
  return 0;
}

/// Resets VmHWM to the current VmRSS (Linux >= 4.0), so that a later VmHWM is the peak of what
/// came after. Returns false where that is not possible.
bool reset_peak_rss() {
  std::ofstream out("/proc/self/clear_refs");
  out << "5";
  out.flush();
  return static_cast<bool>(out);
}

/// glibc raises its mmap threshold (up to 32 MB) each time a large block is freed; from then on,
/// arrays of a few MB come from the brk heap, and the holes they leave when freed stay resident,
/// so the peak would depend on the order of earlier allocations (up to 30 bytes a ball here). A
/// fixed threshold sends every array above 128 KiB to mmap and back to the system when freed: the
/// peak is then that of the memory alive at one time.
void fix_mmap_threshold() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
#endif
}

/// Gives freed heap pages back to the system, so that what the loader freed does not hide the
/// engine's own allocations in the resident set.
void trim_heap() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

struct Options {
  std::filesystem::path world;
  sim::Mode mode = sim::Mode::exact;
  std::optional<std::uint64_t> collisions;
  std::optional<double> sim_seconds;
  std::optional<std::uint64_t> steps;
  std::optional<double> ball_steps;
  double max_wall = 300.0;
};

const turtlegas::bench::Usage usage("gas_bench WORLD.json [--mode exact|step] [--collisions K | --sim-seconds T]"
                                    " [--steps S | --ball-steps B] [--max-wall SECONDS]");

Options parse_options(int argc, char** argv) {
  Options o;
  bool have_world = false;
  for (int k = 1; k < argc; ++k) {
    const std::string_view arg = argv[k];
    auto value = [&]() -> std::string {
      if (k + 1 >= argc) usage.error(std::string(arg) + " needs a value");
      return argv[++k];
    };
    if (arg == "--mode") {
      o.mode = mode_option(usage, value());
    } else if (arg == "--collisions") {
      o.collisions = static_cast<std::uint64_t>(usage.positive(arg, value()));
    } else if (arg == "--sim-seconds") {
      o.sim_seconds = usage.positive(arg, value());
    } else if (arg == "--steps") {
      o.steps = static_cast<std::uint64_t>(usage.positive(arg, value()));
    } else if (arg == "--ball-steps") {
      o.ball_steps = usage.positive(arg, value());
    } else if (arg == "--max-wall") {
      o.max_wall = usage.positive(arg, value());
    } else if (arg == "-h" || arg == "--help") {
      std::cout << "gas_bench: throughput and memory of one world file\n";
      usage.print(std::cout);
      std::exit(0);  // (nothing is open yet)
    } else if (!arg.empty() && arg[0] == '-') {
      usage.error("unknown option '" + std::string(arg) + "'");
    } else if (have_world) {
      usage.error("only one world file per run (each scene gets its own process), got a second: '" + std::string(arg) + "'");
    } else {
      o.world = argv[k];
      have_world = true;
    }
  }
  if (!have_world) usage.error("no world file given");
  if (o.collisions && o.sim_seconds) usage.error("give --collisions or --sim-seconds, not both");
  if (o.steps && o.ball_steps) usage.error("give --steps or --ball-steps, not both");
  if (o.mode == sim::Mode::exact && (o.steps || o.ball_steps)) usage.error("--steps and --ball-steps are for --mode step");
  if (o.mode == sim::Mode::step && (o.collisions || o.sim_seconds))
    usage.error("--collisions and --sim-seconds are for --mode exact; step mode runs --steps or --ball-steps");
  return o;
}

/// What one timed run did.
struct Run {
  double wall = 0.0;  ///< seconds inside advance_to
  double cpu = 0.0;   ///< this thread's CPU seconds inside advance_to
  std::uint64_t chunks = 0;
  bool truncated = false;
  /// After each chunk: simulated time and collisions so far (equal spans with --sim-seconds, so
  /// that a rate's error bar can be taken from batch means).
  std::vector<std::pair<double, std::uint64_t>> chunk_ends;
};

/// Exact mode: advance in chunks of simulated time until the budget is met. The first chunk is
/// short; later ones aim at the collisions still missing at the rate seen so far, at most eight
/// times the time simulated so far, so that a poor early estimate cannot overshoot far.
Run run_exact(sim::World& world, std::optional<std::uint64_t> budget, std::optional<double> sim_seconds,
              double max_wall) {
  Run run;
  const double t0 = world.time();
  auto timed_advance = [&](double t) {
    const double cpu_start = thread_cpu_seconds();
    const auto start = Clock::now();
    world.advance_to(t);
    run.wall += seconds_since(start);
    run.cpu += thread_cpu_seconds() - cpu_start;
    ++run.chunks;
    run.chunk_ends.emplace_back(world.time(), world.stats().collisions());
  };
  if (sim_seconds) {
    // Ten chunks, only so that --max-wall can stop a run that would take too long.
    for (int k = 1; k <= 10 && !run.truncated; ++k) {
      timed_advance(t0 + *sim_seconds * k / 10.0);
      run.truncated = run.wall > max_wall && k < 10;
    }
    return run;
  }
  const auto target = static_cast<double>(*budget);
  double chunk = 0.1;
  for (;;) {
    timed_advance(world.time() + chunk);
    const auto done = static_cast<double>(world.stats().collisions());
    if (done >= target) break;
    // A scene that stops colliding (every ball gone through an open boundary) ends here too.
    if (run.wall > max_wall || run.chunks >= 1000) {
      run.truncated = true;
      break;
    }
    const double elapsed = world.time() - t0;
    const double rate = done / elapsed;  // collisions per simulated second
    // 2% over the estimate, so that the last chunk usually finishes the budget instead of leaving a
    // sliver for one more.
    chunk = rate > 0.0 ? std::min(1.02 * (target - done) / rate, 8.0 * elapsed) : 8.0 * elapsed;
  }
  return run;
}

/// Step mode: whole steps, in up to twenty chunks (for --max-wall). Each chunk ends a millionth of a
/// step past the boundary, so that rounding in k dt cannot leave its last step unfinished.
Run run_steps(sim::World& world, std::uint64_t steps, double max_wall) {
  Run run;
  const double dt = world.dt();
  const std::uint64_t per_chunk = std::max<std::uint64_t>(1, (steps + 19) / 20);
  for (std::uint64_t done = 0; done < steps;) {
    done = std::min(steps, done + per_chunk);
    const double cpu_start = thread_cpu_seconds();
    const auto start = Clock::now();
    world.advance_to((static_cast<double>(done) + 1e-6) * dt);
    run.wall += seconds_since(start);
    run.cpu += thread_cpu_seconds() - cpu_start;
    ++run.chunks;
    if (run.wall > max_wall && done < steps) {
      run.truncated = true;
      break;
    }
  }
  return run;
}

int run_main(int argc, char** argv) {
  fix_mmap_threshold();
  const std::uint64_t baseline_rss = proc_status_bytes("VmRSS");
  const Options opt = parse_options(argc, argv);

  const auto load_start = Clock::now();
  std::optional<sim::WorldDef> def = turtlegas::world::load_world_file(opt.world);
  const double load_seconds = seconds_since(load_start);
  const std::size_t n = def->balls.size();
  if (n == 0) throw std::invalid_argument(opt.world.string() + ": the world has no balls; gas_bench measures ball collisions");
  double disc_area = 0.0;
  for (const auto& b : def->balls) disc_area += std::numbers::pi * b.radius * b.radius;
  const double phi = disc_area / (def->arena.width * def->arena.height);

  const auto construct_start = Clock::now();
  // The World consumes the scene: it frees the ball list as soon as it has copied the balls, so
  // the peak is not the scene plus the whole engine (see World(WorldDef&&)).
  sim::World world(std::move(*def), opt.mode);
  const double construct_seconds = seconds_since(construct_start);
  def.reset();  // the rest of it (walls, names); the engine keeps its own copy of what it needs
  trim_heap();
  const std::uint64_t setup_peak_rss = proc_status_bytes("VmHWM");
  const std::uint64_t engine_rss = proc_status_bytes("VmRSS");
  const bool peak_reset = reset_peak_rss();

  const double energy_start = world.energy();
  Run run;
  if (opt.mode == sim::Mode::exact) {
    const std::uint64_t default_budget = std::max<std::uint64_t>(5'000'000, 10 * static_cast<std::uint64_t>(n));
    run = run_exact(world, opt.sim_seconds ? std::nullopt : std::optional(opt.collisions.value_or(default_budget)),
                    opt.sim_seconds, opt.max_wall);
  } else {
    const double ball_steps = opt.ball_steps.value_or(std::max(1e7, 10.0 * static_cast<double>(n)));
    const std::uint64_t steps = opt.steps.value_or(
        std::max<std::uint64_t>(10, static_cast<std::uint64_t>(std::ceil(ball_steps / static_cast<double>(n)))));
    run = run_steps(world, steps, opt.max_wall);
  }
  const double energy_end = world.energy();
  const sim::Overlap overlap = world.measure_overlap();
  const sim::Overlap contact_overlap = world.max_contact_overlap();
  // After the final overlap check too: the peak of everything the program did.
  const std::uint64_t run_peak_rss = proc_status_bytes("VmHWM");
  const std::uint64_t peak_rss = std::max(setup_peak_rss, run_peak_rss);

  const sim::Stats& s = world.stats();
  const auto collisions = static_cast<double>(s.collisions());
  const auto events = static_cast<double>(s.events);
  const double sim_seconds = world.time();
  const double nd = static_cast<double>(n);
  const double ns = 1e9 * run.wall;
  auto per = [](double a, double b) { return b > 0.0 ? a / b : 0.0; };

  nlohmann::ordered_json out;
  out["world"] = opt.world.stem().string();
  out["N"] = n;
  out["phi"] = phi;
  out["mode"] = std::string(sim::to_string(opt.mode));
  out["collisions"] = s.collisions();
  out["ball_ball"] = s.ball_ball;
  out["ball_wall"] = s.ball_wall + s.ball_wall_end;
  out["events"] = s.events;
  out["cell_crossings"] = s.cell_crossings;
  out["stale"] = s.stale;
  out["steps"] = s.steps;
  out["sim_seconds"] = sim_seconds;
  out["wall_seconds"] = run.wall;
  out["cpu_seconds"] = run.cpu;
  out["chunks"] = run.chunks;
  out["truncated"] = run.truncated;
  out["collisions_per_second"] = per(collisions, run.wall);
  out["ns_per_event"] = per(ns, events);
  out["ns_per_collision"] = per(ns, collisions);
  out["wall_per_sim_second"] = per(run.wall, sim_seconds);
  out["ball_steps_per_second"] = opt.mode == sim::Mode::step ? per(nd * static_cast<double>(s.steps), run.wall) : 0.0;
  out["collisions_per_ball"] = collisions / nd;
  out["peak_rss_bytes"] = peak_rss;
  out["baseline_rss_bytes"] = baseline_rss;
  out["setup_peak_rss_bytes"] = setup_peak_rss;
  out["engine_rss_bytes"] = engine_rss;
  // Whole process, loading and World construction included (the scene as a WorldDef, ids and all,
  // until the World has copied its balls).
  out["bytes_per_ball"] = per(static_cast<double>(peak_rss) - static_cast<double>(baseline_rss), nd);
  // The engine alone: the peak while running, with the WorldDef gone, above the program's start.
  if (peak_reset) {
    out["run_peak_rss_bytes"] = run_peak_rss;
    out["engine_bytes_per_ball"] = per(static_cast<double>(run_peak_rss) - static_cast<double>(baseline_rss), nd);
  } else {
    out["run_peak_rss_bytes"] = nullptr;
    out["engine_bytes_per_ball"] = nullptr;
  }
  out["load_seconds"] = load_seconds;
  out["construct_seconds"] = construct_seconds;
  out["energy_start"] = energy_start;
  out["energy_end"] = energy_end;
  out["energy_drift"] = per(energy_end - energy_start, std::abs(energy_start));
  out["overlap_end"] = overlap.relative;
  out["max_contact_overlap"] = contact_overlap.relative;
  out["cell_size"] = world.cell_size();
  out["cells"] = static_cast<std::uint64_t>(world.cells_x()) * static_cast<std::uint64_t>(world.cells_y());
  out["dt"] = world.dt();
  if (opt.mode == sim::Mode::exact) {
    nlohmann::json ends = nlohmann::json::array();
    for (const auto& [t, c] : run.chunk_ends) ends.push_back({t, c});
    out["chunk_ends"] = ends;  // copied: a json does not move into an ordered_json
  }
  std::cout << out.dump() << '\n';
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return turtlegas::bench::run_with_exit_codes("gas_bench", run_main, argc, argv); }
