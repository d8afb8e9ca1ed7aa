// SPDX-License-Identifier: MIT
#include "run3d.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <memory>
#include <numeric>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <cairo.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "cli_common.hpp"
#include "output_file.hpp"
#include "overlap_budget.hpp"
#include "run_loop.hpp"
#include "signals.hpp"
#include "turtlegas/formats/observables.hpp"
#include "turtlegas/sim/mode_names.hpp"
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
    case sim::Event3Kind::wedged: return "wedged";
  }
  return "?";
}

nlohmann::json vec(sim::Vec3 v) { return nlohmann::json::array({v.x, v.y, v.z}); }

}  // namespace

std::optional<world::World3File> load_world3_if_3d(const std::string& file) {
  // A recording is 2-D and may be huge (a crash can leave a zero-filled tail): its own reader
  // takes it a line at a time; reading it whole here took all memory.
  if (is_recording(file)) return std::nullopt;
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

int run3d(const RunOptions& opt, const world::World3File& file) {
  world::World3File w = file;
  if (opt.mode) {
    const std::optional<sim::Mode> mode = sim::mode_from_string(*opt.mode);
    if (!mode) throw BadInput("--mode " + *opt.mode + ": exact or step");
    w.def.mode = *mode;
  }
  if (opt.dt) w.def.dt = *opt.dt;
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
    observer.emplace(*world, w.def, w.name, o, opt.until, w.wall_ids);
  }
  if (!opt.events.empty()) events_file.emplace(opt.events, "--events");
  if (!opt.state_out.empty()) state_file.emplace(opt.state_out, "--state-out");
  if (!opt.stats_json.empty()) stats_file.emplace(opt.stats_json, "--stats-json");
  const double e0 = world->energy();
  std::vector<sim::Event3> log;
  // Stops as 2-D's run has them (run_loop.hpp): a signal or --max-wall-seconds seen between chunks
  // and, every 4096 events, inside one (with the progress line, so that a chunk that does not end
  // still shows its events), --max-events as the engine's limit.
  install_stop_signals();
  Progress progress(opt.until);
  world->set_stop_poll([&, wall = opt.max_wall_seconds] {
    progress.update(world->time(), world->events(), "");
    return stop_signal() != 0 || (wall && seconds_since(start) >= *wall);
  });
  if (opt.max_events) world->set_event_limit(*opt.max_events);
  Stopped end{Stop::until, 0};
  // The overlap self-check as 2-D's (docs/cli.md, "The overlap self-check"): with the stats asked
  // for, the deepest overlap at the end and at evenly spaced instants of the run, as many as the
  // event budget allows (all of them with --overlap-samples).
  const bool want_stats = opt.stats || !opt.stats_json.empty();
  const std::uint64_t instants = !want_stats ? 0 : opt.overlap_samples ? *opt.overlap_samples : overlap_instants(opt.until, w.def.dt);
  SampleBudget budget(world->sphere_count(), world->wall_count(), opt.overlap_samples.has_value());
  std::uint64_t next_instant = 1;
  auto instant = [&](std::uint64_t k) { return opt.until * static_cast<double>(k) / static_cast<double>(instants); };
  double sampled = 0.0, check_seconds = 0.0, sampled_at = -1.0;
  const std::uint64_t events_at_start = world->events();
  auto measure = [&] {
    const auto check_start = std::chrono::steady_clock::now();
    const double o = world->max_overlap_now();
    check_seconds += seconds_since(check_start);
    return o;
  };
  // Chunks of at most 10^5 events' worth of time would need a rate; a chunk of simulated time
  // that shrinks when the log grows large keeps memory bounded instead.
  double chunk = std::max(opt.until / 1000.0, 1e-9);
  while (world->time() < opt.until && end.first == Stop::until) {
    if (const int sig = stop_signal()) {
      end = {Stop::signal, sig};
      break;
    }
    if (opt.max_wall_seconds && seconds_since(start) >= *opt.max_wall_seconds) {
      end = {Stop::max_wall_seconds, 0};
      break;
    }
    double t = std::min(opt.until, world->time() + chunk);
    if (next_instant <= instants) t = std::min(t, instant(next_instant));
    log.clear();
    try {
      if (observer) observer->advance_to(t);  // stops at its sample times on the way
      else world->advance_to(t, events_file ? &log : nullptr);
    } catch (const sim::StopRequested&) {
      const int sig = stop_signal();
      end = sig ? Stopped{Stop::signal, sig} : Stopped{Stop::max_wall_seconds, 0};
    } catch (const sim::EventLimitReached&) {
      end = {Stop::max_events, 0};
    }
    progress.update(world->time(), world->events(), "");
    if (next_instant <= instants && end.first == Stop::until && world->time() >= instant(next_instant)) {
      while (next_instant <= instants && world->time() >= instant(next_instant)) ++next_instant;
      if (budget.take(world->events() - events_at_start)) sampled = std::max(sampled, measure()), sampled_at = world->time();
    }
    if (events_file) {
      std::string text;
      for (const sim::Event3& e : log) {
        nlohmann::json line{{"t", e.t}, {"kind", kind_name(e.kind)}, {"a", w.ball_ids[e.a]}};
        if (e.kind == sim::Event3Kind::ball_ball) line["b"] = w.ball_ids[e.b];
        else if (e.kind != sim::Event3Kind::exit) line["b"] = w.wall_ids[e.b];
        if (e.kind == sim::Event3Kind::ball_wall_edge) line["edge"] = e.c;
        if (e.kind == sim::Event3Kind::ball_wall_corner) line["corner"] = e.c;
        if (e.kind == sim::Event3Kind::wedged) line["c"] = w.wall_ids[e.c];
        text += line.dump() + "\n";
      }
      events_file->stream() << text;
      if (log.size() > 100000) chunk *= 0.5;
    }
  }
  progress.clear();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (state_file) {
    nlohmann::json balls = nlohmann::json::array();
    for (std::size_t i = 0; i < world->sphere_count(); ++i)
      if (world->alive(i)) balls.push_back({{"id", w.ball_ids[i]}, {"pos", vec(world->position(i))}, {"vel", vec(world->velocity(i))}});
    state_file->stream() << nlohmann::json{{"t", world->time()}, {"balls", balls}, {"turtles", nlohmann::json::array()}}.dump(1) + "\n";
  }
  const double overlap = !want_stats ? 0.0 : sampled_at == world->time() ? sampled : std::max(sampled, measure());
  nlohmann::json stats{{"dimensions", 3},
                       {"mode", std::string(sim::to_string(w.def.mode))},
                       {"collisions", world->collisions()},
                       {"events", world->events()},
                       {"wall_seconds", wall},
                       {"energy_start", e0},
                       {"energy_end", world->energy()},
                       {"max_overlap", overlap},
                       {"overlap_samples", budget.taken},
                       {"check_seconds", check_seconds},
                       {"max_contact_error", world->max_contact_error()},
                       {"wedged", world->wedged()},
                       {"energy_wedged", world->energy_wedged()}};
  if (end.first != Stop::until) stats["stopped"] = stop_name(end);
  const bool moving = std::any_of(w.def.walls.begin(), w.def.walls.end(), [](const sim::Wall3Def& x) { return !x.keys.empty(); });
  if (moving) stats["wall_work"] = world->wall_work();  // energy_end - energy_start at e = 1 (docs/physics.md)
  if (stats_file) stats_file->stream() << stats.dump(1) + "\n";
  if (opt.stats)
    std::printf("3-D %s run to t = %g: %llu collisions, %llu events, energy %.15g -> %.15g, max overlap %.3g r "
                "(the end and %llu instants), %.3f s (the overlap self-check's %.3f s included)\n",
                std::string(sim::to_string(w.def.mode)).c_str(), world->time(), static_cast<unsigned long long>(world->collisions()),
                static_cast<unsigned long long>(world->events()), e0, world->energy(), overlap,
                static_cast<unsigned long long>(budget.taken), wall, check_seconds);
  if (opt.stats && moving) std::printf("  moving walls gave the spheres %.15g of energy (wall_work)\n", world->wall_work());
  if (opt.stats && world->wedged() > 0)
    std::printf("  squeezed %llu wedged, taking %.15g of energy (docs/physics.md, \"3-D: wedged spheres\")\n",
                static_cast<unsigned long long>(world->wedged()), world->energy_wedged());
  if (observe_file) {
    observe_file->stream() << observer->result().dump(1) << '\n';
    observe_file->commit();
  }
  if (events_file) events_file->commit();
  if (state_file) state_file->commit();
  if (stats_file) stats_file->commit();
  if (end.first == Stop::until) return exit_ok;
  spdlog::warn("{}: stopped at t = {} s of {} ({}); the outputs are written up to there", opt.world, fmt(world->time()),
               fmt(opt.until), stop_name(end));
  return exit_code_for(end);
}

namespace {

cairo_status_t write_png_bytes(void* closure, const unsigned char* data, unsigned int length) {
  auto* out = static_cast<std::ostream*>(closure);
  out->write(reinterpret_cast<const char*>(data), length);
  return *out ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_WRITE_ERROR;
}

/// A sphere's grey-blue at depth z: near the viewer (high z) light, far dark.
std::array<double, 3> depth_shade(double z, double depth) {
  const double f = std::clamp(depth > 0.0 ? z / depth : 0.5, 0.0, 1.0);
  return {0.15 + 0.55 * f, 0.25 + 0.55 * f, 0.45 + 0.5 * f};
}

}  // namespace

int render3d(const std::string& file, double at, const std::string& out, double width_px, const world::World3File& w) {
  std::optional<sim::World3> world;
  try {
    world.emplace(w.def);
  } catch (const std::invalid_argument& e) {
    throw BadInput(file + ": " + e.what());
  }
  world->advance_to(at);
  // The orthographic view along -z: x right, y up, nearer spheres (higher z) drawn last, over the
  // farther ones, and lighter.
  const sim::Vec3 size = w.def.size;
  const double scale = width_px / std::max(size.x, size.y);
  const int W = std::max(1, static_cast<int>(std::lround(size.x * scale))), H = std::max(1, static_cast<int>(std::lround(size.y * scale)));
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < world->sphere_count(); ++i)
    if (world->alive(i)) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return world->position(a).z < world->position(b).z; });
  OutputFile o(out, "--out");
  const bool svg = out.size() >= 4 && out.substr(out.size() - 4) == ".svg";
  if (svg) {
    std::string text;
    char b[256];
    std::snprintf(b, sizeof b, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %g %g\">\n", W, H, size.x, size.y);
    text += b;
    text += "<title>" + w.name + " at t = " + fmt(at) + " (3-D, seen along -z)</title>\n";
    std::snprintf(b, sizeof b, "<rect width=\"%g\" height=\"%g\" fill=\"#ffffff\" stroke=\"#444\" stroke-width=\"%g\"/>\n", size.x, size.y, 1.0 / scale);
    text += b;
    text += "<g transform=\"translate(0 " + fmt(size.y) + ") scale(1 -1)\">\n";
    for (std::size_t k = 0; k < w.def.walls.size(); ++k) {
      text += "<polygon points=\"";
      const sim::Vec3 shift = world->wall_shift(k);  // a moving wall where it is at t
      for (const sim::Vec3& c : w.def.walls[k].corners) text += fmt(c.x + shift.x) + "," + fmt(c.y + shift.y) + " ";
      std::snprintf(b, sizeof b, "\" fill=\"#c8b070\" fill-opacity=\"0.35\" stroke=\"#806020\" stroke-width=\"%g\"/>\n", 1.0 / scale);
      text += b;
    }
    for (std::size_t i : order) {
      const sim::Vec3 p = world->position(i);
      const auto c = depth_shade(p.z, size.z);
      std::snprintf(b, sizeof b, "<circle cx=\"%.6g\" cy=\"%.6g\" r=\"%.6g\" fill=\"rgb(%d,%d,%d)\" stroke=\"#102030\" stroke-width=\"%g\"/>\n",
                    p.x, p.y, w.def.spheres[i].radius, static_cast<int>(255 * c[0]), static_cast<int>(255 * c[1]),
                    static_cast<int>(255 * c[2]), 0.5 / scale);
      text += b;
    }
    text += "</g>\n</svg>\n";
    o.stream() << text;
  } else {
    std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)> surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H),
                                                                          cairo_surface_destroy);
    std::unique_ptr<cairo_t, void (*)(cairo_t*)> cr_owner(cairo_create(surface.get()), cairo_destroy);
    cairo_t* cr = cr_owner.get();
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_translate(cr, 0, H);
    cairo_scale(cr, scale, -scale);
    for (std::size_t n = 0; n < w.def.walls.size(); ++n) {
      const sim::Wall3Def& wall = w.def.walls[n];
      const sim::Vec3 shift = world->wall_shift(n);  // a moving wall where it is at t
      for (std::size_t k = 0; k < wall.corners.size(); ++k)
        (k == 0 ? cairo_move_to : cairo_line_to)(cr, wall.corners[k].x + shift.x, wall.corners[k].y + shift.y);
      cairo_close_path(cr);
      cairo_set_source_rgba(cr, 0.78, 0.69, 0.44, 0.35);
      cairo_fill_preserve(cr);
      cairo_set_source_rgb(cr, 0.5, 0.38, 0.13);
      cairo_set_line_width(cr, 1.0 / scale);
      cairo_stroke(cr);
    }
    for (std::size_t i : order) {
      const sim::Vec3 p = world->position(i);
      const double r = w.def.spheres[i].radius;
      const auto c = depth_shade(p.z, size.z);
      // A sphere's shading: lit from the upper left, its colour that of its depth.
      cairo_pattern_t* g = cairo_pattern_create_radial(p.x - 0.35 * r, p.y + 0.35 * r, 0.1 * r, p.x, p.y, r);
      cairo_pattern_add_color_stop_rgb(g, 0.0, std::min(1.0, c[0] + 0.3), std::min(1.0, c[1] + 0.3), std::min(1.0, c[2] + 0.3));
      cairo_pattern_add_color_stop_rgb(g, 1.0, 0.6 * c[0], 0.6 * c[1], 0.6 * c[2]);
      cairo_arc(cr, p.x, p.y, r, 0, 6.283185307179586);
      cairo_set_source(cr, g);
      cairo_fill(cr);
      cairo_pattern_destroy(g);
    }
    cairo_identity_matrix(cr);
    cairo_set_source_rgb(cr, 0.27, 0.27, 0.27);
    cairo_rectangle(cr, 0.5, 0.5, W - 1, H - 1);
    cairo_set_line_width(cr, 1.0);
    cairo_stroke(cr);
    cairo_surface_flush(surface.get());
    if (cairo_surface_write_to_png_stream(surface.get(), write_png_bytes, &o.stream()) != CAIRO_STATUS_SUCCESS)
      throw std::runtime_error("could not write the PNG");
  }
  o.commit();
  return exit_ok;
}

}  // namespace turtlegas::apps
