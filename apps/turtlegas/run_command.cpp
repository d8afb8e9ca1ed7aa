// SPDX-License-Identifier: MIT
#include "run_command.hpp"
#include "run3d.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "checkpoint.hpp"
#include "plugins.hpp"
#include "cli_common.hpp"
#include "output_file.hpp"
#include "overlap_budget.hpp"
#include "scene_scales.hpp"
#include "run_loop.hpp"
#include "signals.hpp"
#include "turtlegas/formats/ball_trails.hpp"
#include "turtlegas/formats/event_log.hpp"
#include "turtlegas/formats/input_log.hpp"
#include "turtlegas/formats/names.hpp"
#include "turtlegas/formats/observables.hpp"
#include "turtlegas/formats/xyz_trajectory.hpp"
#include "turtlegas/formats/recording.hpp"
#include "turtlegas/formats/state_file.hpp"
#include "turtlegas/formats/stats_file.hpp"
#include "turtlegas/formats/svg_snapshot.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/world/entries.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/turtle/game.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::apps {
namespace {

/// What a run adds up besides the engine's own Stats.
struct RunTotals {
  double energy_start = 0.0;
  std::uint64_t touches = 0;
  std::uint64_t faults = 0;
};

/// The --stats summary on stdout.
void print_summary(const formats::RunFigures& run, const sim::World& world, const world::Scene& scene,
                   const turtle::WorldServer* server) {
  using ull = unsigned long long;
  const sim::Stats& st = world.stats();
  const double energy_start = run.energy_start, energy_end = run.energy_end;
  const double de = energy_start != 0.0 ? (energy_end - energy_start) / std::abs(energy_start) : energy_end - energy_start;
  std::printf("%s (%s): %s, %s mode, t = 0 -> %s s%s\n", scene.def.name.c_str(), run.world.c_str(),
              count_summary(scene.def, run.balls).c_str(), sim::to_string(run.mode).data(), fmt(world.time()).c_str(),
              run.stopped.empty() ? "" : (" (stopped early: " + run.stopped + ")").c_str());
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
  if (st.folded > 0)
    std::printf("  folded       %llu elastic wedges, energy kept (docs/physics.md, \"The elastic wedge\")\n",
                ull(st.folded));
  if (st.wedged + st.crushed + st.folded > 0)
    std::printf("  energy rules %s taken (wedged %s, crushed %s, folded %s; docs/physics.md, \"The energy ledger\")\n",
                fmt(st.energy_rules()).c_str(), fmt(st.energy_wedged).c_str(), fmt(st.energy_crushed).c_str(),
                fmt(st.energy_folded).c_str());
  std::printf("  events       %llu  (cell crossings %llu, stale %llu, steps %llu)\n", ull(st.events),
              ull(st.cell_crossings), ull(st.stale), ull(st.steps));
  if (run.resumed == "state")
    std::printf("  resumed      from the engine state at t = %s s (its %llu collisions not simulated here)\n",
                fmt(run.resumed_t).c_str(), ull(run.collisions_before));
  else if (run.resumed == "replay")
    std::printf("  resumed      by replaying the run to t = %s s (counted in the wall time)\n", fmt(run.resumed_t).c_str());
  if (run.check_seconds > 0.0)
    std::printf("  wall time    %.3f s  (%s collisions/s; the overlap self-check's %.3f s left out, docs/cli.md)\n",
                run.wall_seconds, fmt(run.collisions_per_second(st)).c_str(), run.check_seconds);
  else
    std::printf("  wall time    %.3f s  (%s collisions/s)\n", run.wall_seconds, fmt(run.collisions_per_second(st)).c_str());
  std::printf("  energy       %s -> %s  (relative change %.3g)\n", fmt(energy_start).c_str(), fmt(energy_end).c_str(), de);
  std::printf("  max overlap  %s  (%.3g of a radius; at contacts, the end and %llu instants of the run)\n",
              fmt(run.max_overlap).c_str(), run.max_overlap_relative, ull(run.overlap_samples));
}

/// The state file's bytes, hashed: what a checkpoint says the run had reached.
std::uint64_t state_hash(const sim::World& world, const formats::RunNames& names) {
  std::ostringstream s;
  formats::write_state(s, world, names);
  return fnv1a64(s.str());
}

/// The first program of `scene` whose controller does not declare itself restartable: a checkpoint
/// of the scene cannot be resumed (resuming replays every program from the start).
std::optional<std::size_t> first_unrestartable(const world::Scene& scene, const turtle::Registry& registry) {
  for (std::size_t i = 0; i < scene.programs.size(); ++i) {
    const turtle::ControllerInfo* info = registry.info(scene.programs[i].controller);
    if (!info || !info->restartable) return i;
  }
  return std::nullopt;
}

/// The checks a resumed run makes before it starts: the same world (`world_hash`, of the bytes
/// loaded), mode and dt, and programs that replay.
void check_resumable(const Checkpoint& c, const RunOptions& opt, std::uint64_t world_hash, const world::Scene& scene,
                     const turtle::Registry& registry) {
  const std::string where = "--resume " + opt.resume + ": ";
  if (world_hash != c.world_hash)
    throw BadInput(where + "the world file " + opt.world + " is not the one the checkpoint was written for (" + c.world +
                   ", whose bytes hash differently): resume with that world, unchanged");
  if (opt.mode && sim::mode_from_string(*opt.mode) != c.mode)
    throw BadInput(where + "the checkpoint is of a " + std::string(sim::to_string(c.mode)) + " mode run; leave out --mode " +
                   *opt.mode);
  if (opt.dt && *opt.dt != c.dt)
    throw BadInput(where + "the checkpoint is of a run with dt " + fmt(c.dt) + " s; leave out --dt " + fmt(*opt.dt));
  if (!(opt.until > c.t))
    throw BadInput(where + "the checkpoint is at t = " + fmt(c.t) + " s; --until must be later (got " + fmt(opt.until) +
                   ")");
  if (const std::optional<std::size_t> i = first_unrestartable(scene, registry))
    throw BadInput(where + "turtle '" + scene.def.turtles[*i].id + "' runs controller '" + scene.programs[*i].controller +
                   "', which does not declare itself restartable. A checkpoint holds no program state (coroutines "
                   "cannot be saved); resuming replays every program from the start, which only a restartable "
                   "controller does exactly (docs/controllers.md, \"Checkpoints\"). Rerun from the start instead");
}

}  // namespace

CLI::App* add_run_command(CLI::App& app, RunCommandLine& line, std::vector<std::string>& plugins,
                          const char* plugin_help) {
  RunOptions& opt = line.parsed;
  line.plugins = &plugins;
  constexpr double big = std::numeric_limits<double>::max();
  CLI::App* run = app.add_subcommand("run", "Simulate a world file until time T");
  run->add_option("world", opt.world, "World file (format turtlegas-world/1)")->required();
  run->add_option("--until", opt.until, "Simulated time to stop at, seconds")->required()->check(real_in(0, big, "seconds"));
  line.mode_option = run->add_option("--mode", line.mode, "exact (event-driven) or step (the memo's fixed steps)")
                         ->check(CLI::IsMember(sim::mode_names))
                         ->capture_default_str();
  line.dt_option = run->add_option("--dt", line.dt, "Step in seconds (overrides the world file's dt)")
                       ->check(real_in(0, big, "seconds", true));
  run->add_option("--events", opt.events, "Write the event log here (JSON lines; - for standard output)");
  run->add_option("--state-out", opt.state_out, "Write the final state here (JSON; - for standard output)");
  run->add_flag("--stats", opt.stats, "Print a summary of the run");
  run->add_option("--stats-json", opt.stats_json, "Write the run's statistics here (JSON; - for standard output)");
  run->add_option("--svg", opt.svg, "Write an SVG picture of the final state here (- for standard output)");
  run->add_option("--svg-trails", opt.svg_trails,
                  "Draw each ball's path over the last SECONDS of the run in the --svg picture, along its flight "
                  "(curves under fields; the first 1000 balls; exact mode)")
      ->check(real_in(0, big, "seconds", true));
  run->add_option("--plugin", plugins, plugin_help);
  run->add_option("--inputs", opt.inputs,
                  "Replay this input log (written by `turtlegas serve --inputs-out`) into the world's remote turtles");
  add_stack_kib_option(*run, opt.stack_kib);
  add_program_budget_option(*run, opt.program_budget, "the run stops");
  line.limits.add_to(*run, "the run", "outputs written up to there");
  run->add_option("--checkpoint", opt.checkpoint,
                  "Write a checkpoint here at the end, when the run stops early, and every --checkpoint-every");
  line.checkpoint_every_option =
      run->add_option("--checkpoint-every", line.checkpoint_every, "Simulated seconds between checkpoints")
          ->check(real_in(0, big, "seconds", true));
  run->add_option("--resume", opt.resume,
                  "Continue the run a checkpoint was written for (a gas from the engine state it holds; a world with "
                  "turtles is replayed to there)");
  run->add_option("--observe", opt.observe,
                  "Write the gas observables here (JSON; - for standard output): temperature, pressure, collision "
                  "rate, mean free path, speed histogram, density profile, g(r), MSD, VACF and D, per species, per time "
                  "window with error bars");
  run->add_option("--observe-from", opt.observe_from, "Simulated time the observation starts at (equilibration before)")
      ->check(real_in(0, big, "seconds"));
  run->add_option("--observe-window", opt.observe_window,
                  "Seconds per observation window (block); default a tenth of --until minus --observe-from")
      ->check(real_in(0, big, "seconds", true));
  run->add_option("--observe-samples", opt.observe_samples, "State samples per window")
      ->capture_default_str()
      ->check(integer_in(1, 1000000, "samples"));
  run->add_option("--observe-axis", opt.observe_axis, "Axis of the density profile")
      ->capture_default_str()
      ->check(CLI::IsMember({"x", "y"}));
  run->add_option("--observe-bins", opt.observe_bins, "Bins of the density profile")
      ->capture_default_str()
      ->check(integer_in(1, 100000, "bins"));
  run->add_option("--observe-speed-bins", opt.observe_speed_bins, "Bins of the speed histogram (0 to 4 rms speeds)")
      ->capture_default_str()
      ->check(integer_in(1, 100000, "bins"));
  run->add_option("--xyz", opt.xyz,
                  "Write the balls' trajectory here as extended XYZ (OVITO, ASE; VMD reads its first four columns), "
                  "a frame every --xyz-every");
  run->add_option("--xyz-every", opt.xyz_every, "Simulated seconds between --xyz frames (the first at the start)")
      ->check(real_in(0, big, "seconds", true));
  run->add_option("--observe-rdf-bins", opt.observe_rdf_bins, "Bins of the radial distribution function g(r)")
      ->capture_default_str()
      ->check(integer_in(1, 100000, "bins"));
  run->add_option("--observe-rdf-max", opt.observe_rdf_max,
                  "Largest distance of g(r) (default 5 of the largest diameters; at most half the shorter side when "
                  "periodic)")
      ->check(real_in(0, big, "distance", true));
  run->add_option("--overlap-samples", opt.overlap_samples,
                  "With --stats or --stats-json: measure the deepest overlap at this many evenly spaced instants "
                  "besides every contact and the end (0: none; default: at the control steps, at most 1000, as "
                  "many as keep the measures near 5 % of the run: docs/cli.md)")
      ->check(integer_in(0, 1000000000, "samples"));
  run->add_option("--record", opt.record,
                  "Write a recording here (docs/recording.md; play it with `turtlegas replay`, draw it with `render`)");
  run->add_option("--keyframe-seconds", opt.keyframe_seconds, "A recording's keyframe every this many simulated seconds (0: none)")
      ->capture_default_str()
      ->check(real_in(0, big, "seconds"));
  run->add_option("--keyframe-events", opt.keyframe_events, "A recording's keyframe after this many engine events (0: none)")
      ->capture_default_str()
      ->check(integer_in(0, std::numeric_limits<std::int64_t>::max(), "events"));
  return run;
}

int run_command(const RunOptions& opt, const turtle::Registry& registry) {
  const auto start = Clock::now();
  if (opt.checkpoint_every && opt.checkpoint.empty())
    throw BadInput("--checkpoint-every needs --checkpoint F, the file to write the checkpoints to");
  std::optional<Checkpoint> resume;
  if (!opt.resume.empty()) resume = read_checkpoint(opt.resume);
  const sim::Mode mode = resume ? resume->mode : sim::mode_from_string(opt.mode.value_or("exact")).value_or(sim::Mode::exact);

  // Outputs are checked and opened before the run, so a bad path costs nothing; none may be an
  // input (the checkpoint that is resumed may be the one written: it is replaced whole).
  std::vector<NamedPath> inputs{{opt.world, "the world file"}};
  for (const std::string& p : opt.plugins) inputs.push_back({p, "--plugin"});
  std::vector<NamedPath> outputs{{opt.events, "--events"}, {opt.state_out, "--state-out"},
                                 {opt.stats_json, "--stats-json"}, {opt.svg, "--svg"}, {opt.observe, "--observe"}, {opt.xyz, "--xyz"},
                                 {opt.record, "--record"}, {opt.checkpoint, "--checkpoint"}};  // the checkpoint last: see below
  if (opt.stats) outputs.push_back({"-", "--stats"});
  if (!opt.resume.empty()) {
    std::vector<NamedPath> others(outputs.begin(), outputs.end() - (opt.stats ? 2 : 1));
    check_outputs(others, {{opt.resume, "--resume"}});
  }
  check_outputs(outputs, inputs);
  if (const auto w3 = load_world3_if_3d(opt.world)) return run3d(opt, *w3);
  if (opt.checkpoint == "-") throw BadInput("--checkpoint needs a file name, not standard output");
  if (!opt.record.empty()) {
    if (opt.record == "-") throw BadInput("--record needs a file name, not standard output (replay seeks in it)");
    if (!opt.resume.empty())
      throw BadInput("--record with --resume: a recording starts at t = 0; record the run from the start instead");
    if (!opt.inputs.empty())
      throw BadInput("--record with --inputs: a recording does not carry the input log yet; drop one of the two");
  }
  std::optional<OutputFile> events_file, state_file, stats_file, svg_file, observe_file, xyz_file;
  if (!opt.xyz.empty()) {
    if (!(opt.xyz_every > 0.0)) throw BadInput("--xyz needs --xyz-every DT, the simulated seconds between its frames");
    xyz_file.emplace(opt.xyz, "--xyz");
  } else if (opt.xyz_every > 0.0) {
    throw BadInput("--xyz-every sets the frames of --xyz F: give --xyz F as well");
  }
  formats::ObserveOptions observing;
  if (!opt.observe.empty()) {
    observing.from = opt.observe_from;
    observing.window = opt.observe_window;
    observing.samples = opt.observe_samples;
    observing.axis = opt.observe_axis.empty() ? 'y' : opt.observe_axis[0];
    observing.profile_bins = opt.observe_bins;
    observing.speed_bins = opt.observe_speed_bins;
    observing.rdf_bins = opt.observe_rdf_bins;
    observing.rdf_max = opt.observe_rdf_max;
    if (const std::string bad = formats::check_observe(observing, 0.0, opt.until); !bad.empty()) throw BadInput(bad);
    observe_file.emplace(opt.observe, "--observe");
  }
  if (!opt.events.empty()) {
    events_file.emplace(opt.events, "--events");
    events_file->keep_on_busy_loop();  // whole up to the last chunk: kept when a busy loop ends the process
  }
  if (!opt.state_out.empty()) state_file.emplace(opt.state_out, "--state-out");
  if (!opt.stats_json.empty()) stats_file.emplace(opt.stats_json, "--stats-json");
  if (!opt.svg.empty()) svg_file.emplace(opt.svg, "--svg");
  if (!opt.checkpoint.empty()) OutputFile probe(opt.checkpoint, "--checkpoint");  // checks the path only
  // The recording is opened last, once the world is loaded and every option checked (it is written
  // as R.partial and renamed over R when whole: a refused run leaves an existing R as it was).
  std::optional<OutputFile> record_file;

  // The world's bytes are read once: the run, its recording and its checkpoints are of these, even
  // if the file is edited while the run goes on.
  std::string world_bytes;
  world::Scene scene = load(opt.world, registry, world_bytes);
  const std::uint64_t world_hash = fnv1a64(world_bytes);
  sim::WorldDef& def = scene.def;
  if (resume) {
    check_resumable(*resume, opt, world_hash, scene, registry);
    def.dt = resume->dt;
  } else if (opt.dt) {
    def.dt = *opt.dt;
  }
  if (!opt.checkpoint.empty())
    if (const std::optional<std::size_t> i = first_unrestartable(scene, registry))
      spdlog::warn("--checkpoint {}: turtle '{}' runs controller '{}', which is not restartable: the checkpoint will "
                   "be written but can never be resumed (--resume replays every program from the start, which only "
                   "restartable controllers do exactly: docs/controllers.md, \"Checkpoints\")",
                   opt.checkpoint, scene.def.turtles[*i].id, scene.programs[*i].controller);
  const std::size_t ball_count = def.balls.size();
  // For the event log and the state file, kept apart from the scene, which the World may take
  // the balls of (World(WorldDef&&)).
  const formats::IdTable ball_ids = formats::ball_ids(def);

  if (opt.signal_handlers) {
    install_stop_signals();
    install_crash_report(opt.world);
  }

  Progress progress(opt.until);
  RunTotals totals;
  Limits limits;
  limits.max_wall_seconds = opt.max_wall_seconds;
  limits.max_events = opt.max_events;
  limits.checkpoint_every = opt.checkpoint_every;
  if (!opt.record.empty() && opt.keyframe_seconds > 0.0) limits.keyframe_every = opt.keyframe_seconds;
  // The deepest overlap is measured at evenly spaced instants of the run (overlap_samples), not
  // only at contacts and at its end: an overlap the engine does not see (a body sinking without
  // an event, a wall that appears through it) shows in --stats all the same.
  const std::uint64_t instants = !(opt.stats || !opt.stats_json.empty()) ? 0
                                 : opt.overlap_samples                     ? *opt.overlap_samples
                                                                           : overlap_instants(opt.until, def.dt);
  if (instants > 0 && opt.until > 0.0) limits.sample_every = opt.until / static_cast<double>(instants);
  const std::size_t arena_walls = def.arena.boundary == sim::Boundary::walls ? 4 : 0;
  SampleBudget budget(def.balls.size() + def.turtles.size(), def.walls.size() + arena_walls,
                      opt.overlap_samples.has_value());
  sim::Overlap sampled;
  double check_seconds = 0.0;  // in the samples of `sampled`: left out of the collisions per second
  std::optional<formats::RecordingWriter> recorder;
  // Exactly one of these runs the scene: the bare engine, or the world server when there are
  // turtles (which then owns the engine).
  std::optional<sim::World> bare;
  bool restored = false;  // resumed from the checkpoint's engine state, not replayed
  std::uint64_t collisions_restored = 0;  // the restored engine's, not simulated here
  std::unique_ptr<turtle::WorldServer> server;
  std::shared_ptr<formats::ReplayInput> replay;
  if (!opt.inputs.empty()) {
    std::ifstream in(opt.inputs);
    if (!in) throw BadInput("--inputs: cannot read '" + opt.inputs + "'");
    try {
      formats::SpawnApplier spawn = [&registry, file = opt.inputs](turtle::WorldServer& server,
                                                                   const nlohmann::json& entry) {
        try {
          world::spawn_entry(server, entry, file, registry);
        } catch (const std::exception& e) {
          throw std::runtime_error(file + ": a spawn recorded in the log was refused (" + e.what() +
                                   "); is this the log of this world?");
        }
      };
      replay = std::make_shared<formats::ReplayInput>(in, def, opt.inputs, std::move(spawn));
    } catch (const std::invalid_argument& e) {
      throw BadInput(std::string("--inputs: ") + e.what());
    }
  }
  SceneScales scales;
  std::function<std::uint64_t(double)> advance;
  std::function<void(bool)> flush;  // true: write the chunk's events, false: a replay's, dropped
  std::vector<sim::Event> bare_events;
  std::vector<turtle::LogEvent> server_events;
  std::optional<formats::EventLogWriter> writer;
  if (events_file) writer.emplace(events_file->stream());
  double first_chunk = 0.0;
  std::optional<formats::Observer> observer;
  std::optional<formats::BallTrails> trails;
  std::vector<sim::Impulse> trail_impulses;  // when there is no observer to pass them on
  if (opt.svg_trails > 0.0) {
    if (opt.svg.empty()) throw BadInput("--svg-trails draws in the --svg picture: give --svg F as well");
    if (mode != sim::Mode::exact)
      throw BadInput("--svg-trails draws exact mode's flights; leave it out in step mode (or run --mode exact)");
    if (!def.turtles.empty() || replay)
      throw BadInput("--svg-trails draws the balls of a run by the bare engine; " + opt.world +
                     (replay ? " is run with --inputs" : " has turtles (their pen trails are drawn anyway)") +
                     ": leave out --svg-trails");
    trails.emplace(def, std::max(0.0, opt.until - opt.svg_trails));
  }
  if (xyz_file && (!def.turtles.empty() || replay))
    throw BadInput("--xyz writes the balls of a run by the bare engine; " + opt.world +
                   (replay ? " is run with --inputs" : " has turtles") + ": leave out --xyz (a recording, --record, "
                   "keeps turtles)");
  std::optional<formats::XyzWriter> xyz;
  double next_frame = 0.0;
  std::uint64_t frame_k = 0;
  if (observe_file && (!def.turtles.empty() || replay))
    throw BadInput("--observe measures a gas run by the bare engine; " + opt.world +
                   (replay ? " is run with --inputs" : " has turtles") + ": leave out --observe, or the turtles");
  if (def.turtles.empty() && !replay) {
    // The World takes the balls over, so that the scene's copy of them (and their ids' strings)
    // and the engine are never in memory together: a million balls then cost about 170 bytes each
    // rather than 260. def keeps everything else.
    std::vector<sim::BallDef> balls = std::move(def.balls);
    def.balls.clear();
    sim::WorldDef given = def;  // everything but the balls: small
    given.balls = std::move(balls);
    scales = predict_scales(given, mode);
    bare.emplace(make_world(std::move(given), mode, opt.world));
    sim::World& world = *bare;
    totals.energy_start = world.energy();  // at t = 0, resumed or not: --stats says the run's
    if (resume && resume->engine && resume->engine_build != engine_build())
      spdlog::warn("--resume {}: its engine state was written by turtlegas {}, this is {}: it is not used (another "
                   "build may keep its memory otherwise); the run is replayed to t = {} s instead",
                   opt.resume, resume->engine_build, engine_build(), fmt(resume->t));
    else if (resume && resume->engine && !observe_file && !trails) {
      // The checkpoint holds the engine's memory: the world goes on from it (checked below), with
      // nothing simulated twice. --observe and --svg-trails measure from before the checkpoint,
      // which only the replay gives them.
      try {
        world.restore_state(*resume->engine);
      } catch (const std::invalid_argument& e) {
        throw BadInput("--resume " + opt.resume + ": the engine state does not fit " + opt.world + " (" + e.what() +
                       "); the checkpoint is damaged, or of another turtlegas: rerun from the start");
      }
      restored = true;
      collisions_restored = world.stats().collisions();
    }
    world.set_event_log(&bare_events);
    stop_inside_steps(world, limits, start);
    if (observe_file) observer.emplace(world, def, observing, opt.until);
    if (trails && observer) observer->forward = [&trails](const std::vector<sim::Impulse>& b) { trails->take(b); };
    else if (trails) world.set_impulse_log(&trail_impulses);
    // A quarter step first: short enough for a million balls.
    first_chunk = std::min((opt.until - world.time()) / 64.0, def.dt / 4.0);
    if (xyz_file) {
      xyz.emplace(xyz_file->stream(), world, def, ball_ids);
      // Frames at k DT from the first at or after the start (a resumed run's time).
      frame_k = static_cast<std::uint64_t>(std::ceil(world.time() / opt.xyz_every - 1e-9));
      next_frame = static_cast<double>(frame_k) * opt.xyz_every;
    }
    advance = [&world, &observer, &trails, &trail_impulses, &xyz, &xyz_file, &next_frame, &frame_k,
               every = opt.xyz_every](double t) {
      auto step = [&](double u) {
        if (observer) observer->advance_to(u);  // stops at its sample times on the way
        else world.advance_to(u);
        if (trails) trails->take(trail_impulses), trail_impulses.clear();
      };
      auto to = [&](double u) {  // stops at the trajectory's frames on the way
        // (A frame within round-off of u, 30 x 0.1 for 3, is taken at u.)
        while (xyz && next_frame <= u + 1e-12 * std::max(1.0, u)) {
          step(std::clamp(next_frame, world.time(), std::max(u, world.time())));
          xyz->frame(world);
          next_frame = static_cast<double>(++frame_k) * every;
        }
        if (xyz) xyz_file->flush();
        step(u);
      };
      if (trails && !trails->started() && trails->from() <= t) {
        to(trails->from());  // the trails start: a stop there
        trails->start(world);
        trail_impulses.clear();
      }
      to(t);
      return world.stats().events;
    };
    flush = [&, names = formats::RunNames{ball_ids, def, world}](bool write) {
      if (write && writer) {
        writer->write(bare_events, names);
        events_file->flush();
      }
      if (write && recorder) recorder->events(bare_events, names);
      bare_events.clear();
    };
  } else {
    turtle::ServerOptions options;
    options.mode = mode;
    options.stack_bytes = opt.stack_kib * 1024;
    options.program_budget = opt.program_budget;
    options.input = replay;
    scales = predict_scales(def, mode);
    server = make_server(scene, registry, options, opt.world);
    totals.energy_start = server->world().energy();
    // The log is always kept: touches and faults are counted from it.
    server->set_event_log(&server_events);
    stop_inside_steps(*server, limits, start);
    // Whole control steps at first; programs run only at step boundaries anyway.
    first_chunk = def.dt;
    turtle::WorldServer& s = *server;
    advance = [&s](double t) {
      s.run_until(t);  // a BusyLoopError ends the run (exit 1)
      return s.world().stats().events;
    };
    flush = [&](bool write) {
      for (const turtle::LogEvent& e : server_events) {
        totals.touches += e.kind == "touch" ? 1 : 0;
        totals.faults += e.kind == "fault" ? 1 : 0;
      }
      if (write && writer) {
        writer->write(server_events);
        events_file->flush();
      }
      if (write && recorder) recorder->events(server_events);
      server_events.clear();
      if (write) note_run_time(server->world().time());  // how far the event log is whole
    };
  }
  const sim::World& world = server ? server->world() : *bare;
  if (!opt.record.empty()) {
    record_file.emplace(opt.record, "--record", OutputFile::Write::growing);
    formats::RecordingHeader h;
    h.command = "run";
    h.world_file = opt.world;
    h.world = nlohmann::ordered_json::parse(world_bytes);  // loaded above: JSON
    h.mode = sim::to_string(mode);
    h.dt = def.dt;
    h.until = opt.until;
    h.keyframes = {opt.keyframe_seconds, opt.keyframe_events};
    std::vector<std::string> controllers;
    for (const turtle::TurtleProgram& p : scene.programs) controllers.push_back(p.controller);
    h.plugins = plugins_used(controllers);
    recorder.emplace(record_file->stream(), h);
  }
  // Ids by index. With the world server, its scene: bodies spawned by an input log are in it
  // (after the scene's own); their ball ids are packed when they are first needed.
  formats::IdTable spawned_ids;
  auto current_names = [&]() -> formats::RunNames {
    if (!server || (server->scene().balls.size() == ball_ids.size() && server->scene().turtles.size() == def.turtles.size()))
      return {ball_ids, def, world};
    if (spawned_ids.size() != server->scene().balls.size()) spawned_ids = formats::ball_ids(server->scene());
    return {spawned_ids, server->scene(), world};
  };
  // A scene whose scales predict a run that will not finish says so, with numbers, before it
  // starts (check says the same); the chunks start small enough to come back all the same.
  scales.set_cell(world.cell_size());
  for (const std::string& w :
       scale_warnings(scales, opt.until - world.time(), "this run to --until " + fmt(opt.until)))
    spdlog::warn("{}: {}; --max-wall-seconds or --max-events end it cleanly", opt.world, w);
  Pace pace = first_pace(scales, world, first_chunk);

  auto write_checkpoint_at = [&](double t, const std::string& why) {
    Checkpoint c;
    c.world = opt.world;
    c.world_hash = world_hash;
    c.mode = mode;
    c.dt = def.dt;
    c.t = t;
    c.events = world.stats().events;
    c.state_hash = state_hash(world, current_names());
    c.why = why;
    if (bare && bare->can_save_state()) {
      c.engine = bare->save_state();
      c.engine_build = engine_build();
    }
    OutputFile out(opt.checkpoint, "--checkpoint");
    write_checkpoint(out.stream(), c);
    out.commit();
  };

  Stopped end{Stop::until, 0};
  std::string checkpoint_failed;  // why a periodic checkpoint could not be written
  if (resume && restored) {
    // The proof that the engine state is the run's: the state file the checkpoint hashed.
    if (!(world.time() == resume->t && world.stats().events == resume->events &&
          state_hash(world, current_names()) == resume->state_hash))
      throw BadInput("--resume " + opt.resume + ": the engine state does not give the state the checkpoint hashed (t = " +
                     fmt(resume->t) + " s); the checkpoint is damaged, or of another turtlegas: rerun from the start");
  } else if (resume) {
    // The replay: the same run to the checkpoint's time, its events dropped, then the proof that
    // it is the same run.
    Limits to_checkpoint = limits;
    to_checkpoint.until = resume->t;
    to_checkpoint.checkpoint_every.reset();
    end = run_in_chunks(world.time(), world.stats().events, to_checkpoint, pace, start, progress, "replaying: ", advance,
                        [&] { flush(false); }, [](double, const std::string&) {}, [](double, std::uint64_t, bool, bool) {});
    if (end.first == Stop::until) {
      const bool same = world.time() == resume->t && world.stats().events == resume->events &&
                        state_hash(world, current_names()) == resume->state_hash;
      if (!same)
        throw std::runtime_error("--resume " + opt.resume + ": replaying the run to t = " + fmt(resume->t) +
                                 " s did not arrive at the checkpoint's state (a controller that is not "
                                 "deterministic, or a different turtlegas?); rerun from the start");
    }
  }
  if (recorder) recorder->keyframe(world, current_names());  // the first, at the start
  if (end.first == Stop::until) try {
    limits.until = opt.until;
    const std::uint64_t events_at_start = world.stats().events;
    end = run_in_chunks(world.time(), world.stats().events, limits, pace, start, progress, "", advance, [&] { flush(true); },
                        [&](double t, const std::string& why) {
                          // A checkpoint that cannot be written (a full disk) stops the checkpoints,
                          // not the run: its other outputs are written whole, and it exits 1.
                          if (!checkpoint_failed.empty()) return;
                          try {
                            write_checkpoint_at(t, why);
                          } catch (const std::runtime_error& e) {
                            checkpoint_failed = e.what();
                            spdlog::error("{}; the run goes on without checkpoints, its other outputs are written",
                                          checkpoint_failed);
                          }
                        },
                        [&](double, std::uint64_t events, bool at_key, bool at_sample) {
                          if (recorder && (at_key || recorder->keyframe_due(events))) recorder->keyframe(world, current_names());
                          if (at_sample && budget.take(events - events_at_start)) {
                            const auto check_start = Clock::now();
                            const sim::Overlap o = world.measure_overlap();
                            check_seconds += seconds_since(check_start);
                            sampled.depth = std::max(sampled.depth, o.depth);
                            sampled.relative = std::max(sampled.relative, o.relative);
                          }
                        });
  } catch (const turtle::BusyLoopError&) {
    // A busy loop stopped at a safe point: the event log is kept up to the stop (the run fails).
    flush(true);
    if (events_file) events_file->commit();
    throw;
  }
  progress.clear();
  if (server) {
    server->set_event_log(nullptr);
  } else {
    bare->set_event_log(nullptr);
    if (observer) observer->detach();
    if (trails) {
      trails->take(trail_impulses);
      trails->finish(*bare);
      bare->set_impulse_log(nullptr);
    }
  }
  const std::string stopped = stop_name(end);

  formats::RunFigures run;
  run.world = opt.world;
  run.name = def.name;
  run.mode = mode;
  run.until = opt.until;
  run.t = world.time();
  run.stopped = stopped;
  run.dt = def.dt;
  run.seed = def.seed;
  run.balls = ball_count;
  run.turtles = def.turtles.size();
  run.touches = totals.touches;
  run.faults = totals.faults;
  run.wall_seconds = seconds_since(start);
  run.check_seconds = check_seconds;
  run.energy_start = totals.energy_start;
  run.overlap_samples = budget.taken;
  if (resume) {
    run.resumed = restored ? "state" : "replay";
    run.resumed_t = resume->t;
    run.collisions_before = collisions_restored;
  }
  finish_run(run, world, server.get(), sampled);

  if (events_file) events_file->commit();
  if (recorder) {
    recorder->keyframe(world, current_names());  // the last, at the end (none when one is there already)
    recorder->finish(world.time(), stopped);
    record_file->commit();
  }
  if (state_file) {
    formats::write_state(state_file->stream(), world, current_names());
    state_file->commit();
  }
  if (stats_file) {
    run.ball_name = [&](std::size_t i) { return std::string(current_names().ball(i)); };
    formats::write_stats(stats_file->stream(), run, world);
    stats_file->commit();
  }
  if (observe_file) {
    observe_file->stream() << observer->result().dump(1) << '\n';
    observe_file->commit();
  }
  if (xyz_file) xyz_file->commit();
  if (svg_file) {
    formats::Snapshot picture = server ? formats::snapshot_of(*server, def) : formats::snapshot_of(world, def);
    if (trails) picture.ball_trails = trails->polylines();
    formats::write_svg(svg_file->stream(), picture);
    svg_file->commit();
  }
  // A resumed run stopped while it was still replaying has got no further than its checkpoint:
  // the checkpoint (perhaps the very file resumed from) is left as it was.
  const bool short_of_resume = resume && world.time() < resume->t;
  if (!opt.checkpoint.empty() && !short_of_resume) {
    try {
      write_checkpoint_at(world.time(), stopped.empty() ? "the end of the run" : stopped);
      checkpoint_failed.clear();  // the last one is whole
    } catch (const std::runtime_error& e) {
      checkpoint_failed = e.what();
      spdlog::error("{}; the run's other outputs are written whole", checkpoint_failed);
    }
  }
  if (opt.stats) print_summary(run, world, scene, server.get());
  if (!checkpoint_failed.empty()) return exit_failure;
  if (end.first == Stop::until) return exit_ok;
  spdlog::warn("{}: stopped at t = {} s of {} ({}); the outputs are written up to there{}", opt.world,
               fmt(world.time()), fmt(opt.until), stopped,
               opt.checkpoint.empty() ? "" : "; continue with --resume " + opt.checkpoint);
  return exit_code_for(end);
}

}  // namespace turtlegas::apps
