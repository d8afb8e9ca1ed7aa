// SPDX-License-Identifier: MIT
#include "run_command.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "atomic_file.hpp"
#include "cli_common.hpp"
#include "turtlegas/formats/event_log.hpp"
#include "turtlegas/formats/names.hpp"
#include "turtlegas/formats/state_file.hpp"
#include "turtlegas/formats/stats_file.hpp"
#include "turtlegas/formats/svg_snapshot.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/turtle/game.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::apps {
namespace {

using Clock = std::chrono::steady_clock;

/// Simulated time / until on stderr, refreshed in place, only on a terminal and only once a run
/// has taken long enough for it to help.
class Progress {
 public:
  explicit Progress(double until) : until_(until), start_(Clock::now()), enabled_(::isatty(STDERR_FILENO) != 0) {}

  void update(double t, std::uint64_t events) {
    if (!enabled_) return;
    const auto now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    if (elapsed < 2.0 || now - last_ < std::chrono::milliseconds(200)) return;
    last_ = now;
    const double pct = until_ > 0.0 ? 100.0 * t / until_ : 100.0;
    std::fprintf(stderr, "\r  t = %.6g / %.6g s  %5.1f%%  %.3g events/s ", t, until_, pct,
                 static_cast<double>(events) / elapsed);
    std::fflush(stderr);
    shown_ = true;
  }
  ~Progress() { clear(); }
  void clear() {
    if (shown_) std::fputs("\r\033[K", stderr), std::fflush(stderr);
    shown_ = false;
  }

 private:
  double until_;
  Clock::time_point start_;
  Clock::time_point last_{};
  bool enabled_;
  bool shown_ = false;
};


/// What a run adds up besides the engine's own Stats.
struct RunTotals {
  double wall_seconds = 0.0;
  double energy_start = 0.0;
  std::uint64_t touches = 0;
  std::uint64_t faults = 0;
  std::size_t turtles_finished = 0;
};

/// Advances in chunks so the event buffer stays bounded and progress can be shown; the physics
/// does not depend on where a run is cut. `advance(t)` runs to t and returns the events since the
/// last call, which `flush` gets. Chunks start at `first_chunk` and adapt to about 0.1 s of wall
/// time, but never drop below `min_chunk`.
template <class Advance, class Flush>
double run_in_chunks(double from, double until, double first_chunk, double min_chunk, Progress& progress,
                     Advance&& advance, Flush&& flush) {
  const auto start = Clock::now();
  double t = from;
  double chunk = first_chunk;
  while (t < until) {
    double next = std::min(until, t + chunk);
    if (!(next > t)) next = until;
    const auto chunk_start = Clock::now();
    const auto [events, total_events] = advance(next);
    const double took = std::chrono::duration<double>(Clock::now() - chunk_start).count();
    flush();
    if ((took > 0.25 || events > (1u << 20)) && chunk / 2.0 >= min_chunk) chunk /= 2.0;
    else if (took < 0.05 && events < (1u << 18)) chunk *= 2.0;
    t = next;
    progress.update(t, total_events);
  }
  return std::chrono::duration<double>(Clock::now() - start).count();
}


/// The --stats summary on stdout.
void print_summary(const formats::RunFigures& run, const sim::World& world, const world::Scene& scene,
                   const turtle::WorldServer* server) {
  using ull = unsigned long long;
  const sim::Stats& st = world.stats();
  const double energy_start = run.energy_start, energy_end = run.energy_end;
  const double de = energy_start != 0.0 ? (energy_end - energy_start) / std::abs(energy_start) : energy_end - energy_start;
  std::printf("%s (%s): %s, %s mode, t = 0 -> %s s\n", scene.def.name.c_str(), run.world.c_str(), count_summary(scene.def, run.balls).c_str(),
              sim::to_string(run.mode).data(), fmt(world.time()).c_str());
  std::printf("  collisions   %llu  (ball-ball %llu, ball-wall %llu, ball-wall-end %llu)\n", ull(st.collisions()),
              ull(st.ball_ball), ull(st.ball_wall), ull(st.ball_wall_end));
  if (!scene.def.turtles.empty()) {
    std::printf("  turtles      %zu  (turtle-wall %llu, turtle-wall-end %llu, turtle-turtle %llu, turtle-ball %llu)\n",
                scene.def.turtles.size(), ull(st.turtle_wall), ull(st.turtle_wall_end), ull(st.turtle_turtle),
                ull(st.turtle_ball));
    std::printf("  programs     %s  (touches %llu, faults %llu, finished %zu)\n", controller_summary(scene).c_str(),
                ull(run.touches), ull(run.faults), run.turtles_finished);
  }
  if (server && server->game()) {  // the tag referee's score (game.hpp)
    const nlohmann::json g = server->game()->score(world.time());
    std::string line;
    for (const auto& t : g.at("turtles"))
      line += (line.empty() ? "" : ", ") + t.at("id").get<std::string>() + " " + fmt(t.at("time_it").get<double>()) +
              " s/" + std::to_string(t.at("tags").get<std::size_t>());
    std::printf("  tag          it now %s; time as it/tags made: %s\n", g.at("it").get<std::string>().c_str(),
                line.c_str());
  }
  std::printf("  exits        %llu  (%zu balls left)\n", ull(st.exits), run.balls_alive);
  if (st.wedged + st.crushed > 0)
    std::printf("  squeezed     %llu wedged, %llu crushed (docs/physics.md)\n", ull(st.wedged), ull(st.crushed));
  std::printf("  events       %llu  (cell crossings %llu, stale %llu, steps %llu)\n", ull(st.events),
              ull(st.cell_crossings), ull(st.stale), ull(st.steps));
  std::printf("  wall time    %.3f s  (%s collisions/s)\n", run.wall_seconds, fmt(run.collisions_per_second(st)).c_str());
  std::printf("  energy       %s -> %s  (relative change %.3g)\n", fmt(energy_start).c_str(), fmt(energy_end).c_str(), de);
  std::printf("  max overlap  %s  (%.3g of a radius)\n", fmt(run.max_overlap).c_str(), run.max_overlap_relative);
}

}  // namespace

CLI::App* add_run_command(CLI::App& app, RunCommandLine& line, std::vector<std::string>& plugins,
                          const char* plugin_help) {
  RunOptions& opt = line.parsed;
  CLI::App* run = app.add_subcommand("run", "Simulate a world file until time T");
  run->add_option("world", opt.world, "World file (format turtlegas-world/1)")->required();
  run->add_option("--until", opt.until, "Simulated time to stop at, seconds")->required();
  run->add_option("--mode", opt.mode, "exact (event-driven) or step (the memo's fixed steps)")
      ->check(CLI::IsMember(sim::mode_names))
      ->capture_default_str();
  line.dt_option = run->add_option("--dt", line.dt, "Step in seconds (overrides the world file's dt)");
  run->add_option("--events", opt.events, "Write the event log here (JSON lines)");
  run->add_option("--state-out", opt.state_out, "Write the final state here (JSON)");
  run->add_flag("--stats", opt.stats, "Print a summary of the run");
  run->add_option("--stats-json", opt.stats_json, "Write the run's statistics here (JSON)");
  run->add_option("--svg", opt.svg, "Write an SVG picture of the final state here");
  run->add_option("--plugin", plugins, plugin_help);
  run->add_option("--stack-kib", opt.stack_kib, "Each turtle program's stack, KiB (a guard page is added)")
      ->capture_default_str();
  run->add_option("--program-budget", opt.program_budget,
                  "Wall-clock seconds a turtle program may run without issuing a command before the run stops")
      ->capture_default_str();

  return run;
}

int run_command(const RunOptions& opt, const turtle::Registry& registry) {
  if (!std::isfinite(opt.until) || opt.until < 0.0)
    throw BadInput("--until must be a finite time >= 0 in seconds (got " + fmt(opt.until) + ")");
  if (opt.dt && (!std::isfinite(*opt.dt) || *opt.dt <= 0.0))
    throw BadInput("--dt must be a finite time > 0 in seconds (got " + fmt(*opt.dt) + ")");
  constexpr std::size_t min_stack_kib = 16, max_stack_kib = 1024 * 1024;
  if (opt.stack_kib < min_stack_kib || opt.stack_kib > max_stack_kib)
    throw BadInput("--stack-kib must be from " + std::to_string(min_stack_kib) + " to " + std::to_string(max_stack_kib) +
                   " (got " + std::to_string(opt.stack_kib) + ")");
  if (!std::isfinite(opt.program_budget) || opt.program_budget <= 0.0)
    throw BadInput("--program-budget must be a finite time > 0 in seconds of wall clock (got " +
                   fmt(opt.program_budget) + ")");
  const sim::Mode mode = sim::mode_from_string(opt.mode).value_or(sim::Mode::exact);  // CLI11 checked it

  // Outputs are opened before the run, so a bad path costs nothing.
  std::optional<AtomicFile> events_file, state_file, stats_file, svg_file;
  if (!opt.events.empty()) events_file.emplace(opt.events, "--events");
  if (!opt.state_out.empty()) state_file.emplace(opt.state_out, "--state-out");
  if (!opt.stats_json.empty()) stats_file.emplace(opt.stats_json, "--stats-json");
  if (!opt.svg.empty()) svg_file.emplace(opt.svg, "--svg");

  world::Scene scene = load(opt.world, registry);
  sim::WorldDef& def = scene.def;
  if (opt.dt) def.dt = *opt.dt;
  const std::size_t ball_count = def.balls.size();
  // For the event log and the state file, kept apart from the scene, which the World may take
  // the balls of (World(WorldDef&&)).
  const formats::IdTable ball_ids = formats::ball_ids(def);

  Progress progress(opt.until);
  RunTotals totals;
  // Exactly one of these runs the scene: the bare engine, or the world server when there are
  // turtles (which then owns the engine).
  std::optional<sim::World> bare;
  std::unique_ptr<turtle::WorldServer> server;
  if (def.turtles.empty()) {
    // The World takes the balls over, so that the scene's copy of them (and their ids' strings)
    // and the engine are never in memory together: a million balls then cost about 170 bytes each
    // rather than 260. def keeps everything else.
    // (the ids' own strings go with the balls)
    std::vector<sim::BallDef> balls = std::move(def.balls);
    def.balls.clear();
    sim::WorldDef given = def;  // everything but the balls: small
    given.balls = std::move(balls);
    bare.emplace(make_world(std::move(given), mode, opt.world));
    sim::World& world = *bare;
    totals.energy_start = world.energy();
    std::vector<sim::Event> events;
    std::optional<formats::EventLogWriter> writer;
    const formats::RunNames names{ball_ids, def, world};
    if (events_file) {
      writer.emplace(events_file->stream());
      world.set_event_log(&events);
    }
    // A quarter step first: short enough for a million balls.
    totals.wall_seconds = run_in_chunks(
        world.time(), opt.until, std::min((opt.until - world.time()) / 64.0, def.dt / 4.0), 0.0, progress,
        [&](double t) {
          world.advance_to(t);
          return std::pair{events.size(), world.stats().events};
        },
        [&] {
          if (writer) writer->write(events, names);
          events.clear();
        });
    world.set_event_log(nullptr);
  } else {
    turtle::ServerOptions options;
    options.mode = mode;
    options.stack_bytes = opt.stack_kib * 1024;
    options.program_budget = opt.program_budget;
    server = make_server(scene, registry, options, opt.world);
    totals.energy_start = server->world().energy();
    // The log is always kept: touches and faults are counted from it.
    std::vector<turtle::LogEvent> events;
    std::optional<formats::EventLogWriter> writer;
    if (events_file) writer.emplace(events_file->stream());
    server->set_event_log(&events);
    // Whole control steps at first; programs run only at step boundaries anyway.
    totals.wall_seconds = run_in_chunks(
        server->time(), opt.until, def.dt, def.dt, progress,
        [&](double t) {
          server->run_until(t);  // a BusyLoopError ends the run (exit 1)
          return std::pair{events.size(), server->world().stats().events};
        },
        [&] {
          for (const turtle::LogEvent& e : events) {
            totals.touches += e.kind == "touch" ? 1 : 0;
            totals.faults += e.kind == "fault" ? 1 : 0;
          }
          if (writer) writer->write(events);
          events.clear();
        });
    server->set_event_log(nullptr);
    for (std::size_t i = 0; i < server->turtle_count(); ++i) totals.turtles_finished += server->turtle(i).finished ? 1 : 0;
  }
  progress.clear();
  const sim::World& world = server ? server->world() : *bare;

  const sim::Overlap now = world.measure_overlap(), seen = world.max_contact_overlap();
  formats::RunFigures run;
  run.world = opt.world;
  run.name = def.name;
  run.mode = mode;
  run.until = opt.until;
  run.dt = def.dt;
  run.seed = def.seed;
  run.balls = ball_count;
  for (std::size_t i = 0; i < world.ball_count(); ++i) run.balls_alive += world.ball(i).alive ? 1 : 0;
  run.turtles = def.turtles.size();
  run.turtles_finished = totals.turtles_finished;
  run.touches = totals.touches;
  run.faults = totals.faults;
  run.wall_seconds = totals.wall_seconds;
  run.energy_start = totals.energy_start;
  run.energy_end = world.energy();
  run.max_overlap = std::max(now.depth, seen.depth);
  run.max_overlap_relative = std::max(now.relative, seen.relative);

  if (events_file) events_file->commit();
  if (state_file) {
    formats::write_state(state_file->stream(), world, formats::RunNames{ball_ids, def, world});
    state_file->commit();
  }
  if (stats_file) {
    formats::write_stats(stats_file->stream(), run, world);
    stats_file->commit();
  }
  if (svg_file) {
    formats::write_svg(svg_file->stream(), server ? formats::snapshot_of(*server, def) : formats::snapshot_of(world, def));
    svg_file->commit();
  }
  if (opt.stats) print_summary(run, world, scene, server.get());
  return exit_ok;
}

}  // namespace turtlegas::apps
