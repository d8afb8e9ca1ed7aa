// SPDX-License-Identifier: MIT
#include "run3d.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "output_file.hpp"
#include "turtlegas/formats/observables.hpp"
#include "turtlegas/world/file_error.hpp"

namespace turtlegas::apps {
namespace {

const char* kind_name(sim::Event3Kind k) {
  switch (k) {
    case sim::Event3Kind::ball_ball: return "ball-ball";
    case sim::Event3Kind::ball_wall: return "ball-wall";
    case sim::Event3Kind::ball_wall_edge: return "ball-wall-edge";
    case sim::Event3Kind::ball_wall_corner: return "ball-wall-corner";
    case sim::Event3Kind::exit: return "exit";
  }
  return "?";
}

nlohmann::json vec(sim::Vec3 v) { return nlohmann::json::array({v.x, v.y, v.z}); }

}  // namespace

std::optional<world::World3File> load_world3_if_3d(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  if (!world::is_world3_text(s)) return std::nullopt;
  try {
    return world::parse_world3(s, file);
  } catch (const world::WorldFileError& e) {
    throw BadInput(e.what());
  }
}

int check3d(const std::string& file, const world::World3File& w) {
  try {
    sim::World3 world(w.def);
    std::printf("%s: ok: 3-D, %zu balls, %zu walls (faces, edges and corners), arena %g x %g x %g\n", file.c_str(),
                world.sphere_count(), world.wall_count(), w.def.size.x, w.def.size.y, w.def.size.z);
  } catch (const std::invalid_argument& e) {
    throw BadInput(file + ": " + e.what());
  }
  return exit_ok;
}

int run3d(const RunOptions& opt, const world::World3File& w) {
  if (opt.mode && *opt.mode != "exact") throw BadInput("--mode step is not simulated in 3-D yet; use --mode exact");
  for (const auto& [set, name] : {std::pair{!opt.svg.empty(), "--svg"},
                                  {!opt.record.empty(), "--record"}, {!opt.checkpoint.empty(), "--checkpoint"},
                                  {!opt.resume.empty(), "--resume"}, {!opt.inputs.empty(), "--inputs"}})
    if (set) throw BadInput(std::string(name) + " does not read 3-D worlds yet; drop it");
  const auto start = std::chrono::steady_clock::now();
  std::optional<sim::World3> world;
  try {
    world.emplace(w.def);
  } catch (const std::invalid_argument& e) {
    throw BadInput(opt.world + ": " + e.what());
  }
  std::optional<OutputFile> events_file, state_file, stats_file, observe_file;
  std::optional<formats::Observer> observer;
  if (!opt.observe.empty()) {
    if (!opt.events.empty())
      throw BadInput("--observe and --events of a 3-D world are not written by one run yet; run it twice");
    formats::ObserveOptions o;
    o.from = opt.observe_from;
    o.window = opt.observe_window;
    o.samples = opt.observe_samples;
    o.axis = opt.observe_axis.empty() ? 'y' : opt.observe_axis[0];
    o.profile_bins = opt.observe_bins;
    o.speed_bins = opt.observe_speed_bins;
    o.rdf_bins = opt.observe_rdf_bins;
    o.rdf_max = opt.observe_rdf_max;
    if (const std::string bad = formats::check_observe(o, 0.0, opt.until); !bad.empty()) throw BadInput(bad);
    observe_file.emplace(opt.observe, "--observe");
    observer.emplace(*world, w.def, w.name, o, opt.until);
  }
  if (!opt.events.empty()) events_file.emplace(opt.events, "--events");
  if (!opt.state_out.empty()) state_file.emplace(opt.state_out, "--state-out");
  if (!opt.stats_json.empty()) stats_file.emplace(opt.stats_json, "--stats-json");
  const double e0 = world->energy();
  std::vector<sim::Event3> log;
  // Chunks of at most 10^5 events' worth of time would need a rate; a chunk of simulated time
  // that shrinks when the log grows large keeps memory bounded instead.
  double chunk = std::max(opt.until / 1000.0, 1e-9);
  while (world->time() < opt.until) {
    const double t = std::min(opt.until, world->time() + chunk);
    log.clear();
    if (observer) observer->advance_to(t);  // stops at its sample times on the way
    else world->advance_to(t, events_file ? &log : nullptr);
    if (opt.max_events && world->events() >= *opt.max_events) break;
    if (events_file) {
      std::string text;
      for (const sim::Event3& e : log) {
        nlohmann::json line{{"t", e.t}, {"kind", kind_name(e.kind)}, {"a", w.ball_ids[e.a]}};
        if (e.kind == sim::Event3Kind::ball_ball) line["b"] = w.ball_ids[e.b];
        else if (e.kind != sim::Event3Kind::exit) line["b"] = w.wall_ids[e.b];
        if (e.kind == sim::Event3Kind::ball_wall_edge) line["edge"] = e.c;
        if (e.kind == sim::Event3Kind::ball_wall_corner) line["corner"] = e.c;
        text += line.dump() + "\n";
      }
      events_file->stream() << text;
      if (log.size() > 100000) chunk *= 0.5;
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (state_file) {
    nlohmann::json balls = nlohmann::json::array();
    for (std::size_t i = 0; i < world->sphere_count(); ++i)
      if (world->alive(i)) balls.push_back({{"id", w.ball_ids[i]}, {"pos", vec(world->position(i))}, {"vel", vec(world->velocity(i))}});
    state_file->stream() << nlohmann::json{{"t", world->time()}, {"balls", balls}, {"turtles", nlohmann::json::array()}}.dump(1) + "\n";
  }
  const double overlap = world->sphere_count() <= 4096 ? world->max_overlap_now() : 0.0;
  nlohmann::json stats{{"dimensions", 3},
                       {"collisions", world->collisions()},
                       {"events", world->events()},
                       {"wall_seconds", wall},
                       {"energy_start", e0},
                       {"energy_end", world->energy()},
                       {"max_overlap", std::max(overlap, 0.0)},
                       {"max_contact_error", world->max_contact_error()}};
  if (stats_file) stats_file->stream() << stats.dump(1) + "\n";
  if (opt.stats)
    std::printf("3-D run to t = %g: %llu collisions, %llu events, energy %.15g -> %.15g, max overlap %.3g r, %.3f s\n",
                world->time(), static_cast<unsigned long long>(world->collisions()),
                static_cast<unsigned long long>(world->events()), e0, world->energy(), std::max(overlap, 0.0), wall);
  if (observe_file) {
    observe_file->stream() << observer->result().dump(1) << '\n';
    observe_file->commit();
  }
  if (events_file) events_file->commit();
  if (state_file) state_file->commit();
  if (stats_file) stats_file->commit();
  return exit_ok;
}

}  // namespace turtlegas::apps
