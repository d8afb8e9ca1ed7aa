// SPDX-License-Identifier: MIT
#include "render_command.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <cairo.h>
#include <spdlog/spdlog.h>

#include "cli_common.hpp"
#include "output_file.hpp"
#include "run_loop.hpp"
#include "scene_scales.hpp"
#include "signals.hpp"
#include "turtlegas/formats/recording.hpp"
#include "turtlegas/formats/svg_snapshot.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/turtle/game.hpp"
#include "turtlegas/turtle/view.hpp"
#include "turtlegas/world/file_error.hpp"
#include "turtlegas/world/world_file.hpp"

extern char** environ;

namespace turtlegas::apps {
namespace fs = std::filesystem;
namespace {

/// The scene to draw and how it runs: a world file's, or a recording's (re-simulated).
struct Source {
  world::Scene scene;
  sim::Mode mode = sim::Mode::exact;
  std::optional<double> end;  ///< a recording: the last time it vouches for
};

bool is_recording(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(64, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head.rfind("{\"format\":\"turtlegas-recording/", 0) == 0;
}

Source load_source(const std::string& path, const turtle::Registry& registry) {
  Source s;
  if (!is_recording(path)) {
    s.scene = load(path, registry);
    return s;
  }
  formats::Recording rec;
  try {
    rec = formats::read_recording(path);
  } catch (const std::invalid_argument& e) {
    throw BadInput(e.what());
  }
  if (!rec.warning.empty()) spdlog::warn("{}", rec.warning);
  try {
    s.scene = world::parse_scene(rec.header.world.dump(), rec.header.world_file + " (recorded in " + path + ")", registry);
  } catch (const world::WorldFileError& e) {
    throw BadInput(path + ": the recorded world does not load here: " + std::string(e.what()));
  }
  s.scene.def.dt = rec.header.dt;
  s.mode = sim::mode_from_string(rec.header.mode).value_or(sim::Mode::exact);
  s.end = rec.end;
  return s;
}

// ---- drawing: the SVG snapshot's look (formats/src/svg_snapshot.cpp), through cairo ----------------

constexpr std::array<std::array<int, 3>, 5> palette = {{{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}};
constexpr std::array<std::array<int, 3>, 10> turtle_colours = {{{0x4e, 0x79, 0xa7}, {0xf2, 0x8e, 0x2b}, {0xe1, 0x57, 0x59},
                                                                {0x76, 0xb7, 0xb2}, {0x59, 0xa1, 0x4f}, {0xed, 0xc9, 0x48},
                                                                {0xb0, 0x7a, 0xa1}, {0xff, 0x9d, 0xa7}, {0x9c, 0x75, 0x5f},
                                                                {0xba, 0xb0, 0xac}}};

void set_rgb(cairo_t* cr, const std::array<int, 3>& c, double alpha = 1.0) {
  cairo_set_source_rgba(cr, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0, alpha);
}
void set_grey(cairo_t* cr, int v) { cairo_set_source_rgb(cr, v / 255.0, v / 255.0, v / 255.0); }

std::array<int, 3> speed_colour(double u) {
  u = std::clamp(u, 0.0, 1.0) * (palette.size() - 1);
  const auto k = std::min(static_cast<std::size_t>(u), palette.size() - 2);
  const double f = u - static_cast<double>(k);
  std::array<int, 3> rgb{};
  for (int c = 0; c < 3; ++c) rgb[c] = static_cast<int>(std::lround(palette[k][c] + f * (palette[k + 1][c] - palette[k][c])));
  return rgb;
}

/// A stroke `px` pixels wide whatever the world-to-pixel scale.
void stroke_px(cairo_t* cr, double px) {
  cairo_save(cr);
  cairo_identity_matrix(cr);
  cairo_set_line_width(cr, px);
  cairo_stroke(cr);
  cairo_restore(cr);
}

/// The window of the world a picture shows: the rectangle of size w x h centred on (cx, cy),
/// turned by `angle` (radians, Logo convention: the picture's up is that heading).
struct Window {
  double cx = 0.0, cy = 0.0, w = 0.0, h = 0.0, angle = 0.0;
};

/// The layout of write_svg: margins, a title line, the window scaled so that its longer side is
/// width_px, and a legend column on the right when there are balls.
struct Layout {
  double scale = 1.0, margin = 12.0, title_h = 30.0, legend_w = 90.0, top = 42.0;
  int width = 0, height = 0;
};

Layout layout_for(const Window& win, double width_px) {
  Layout l;
  l.scale = width_px / std::max(win.w, win.h);
  l.top = l.title_h + l.margin;
  l.width = static_cast<int>(std::ceil(win.w * l.scale + 2 * l.margin + l.legend_w));
  l.height = static_cast<int>(std::ceil(std::max(win.h * l.scale, 160.0) + l.title_h + 2 * l.margin));
  return l;
}

cairo_status_t write_to_stream(void* closure, const unsigned char* data, unsigned int length) {
  auto* out = static_cast<std::ostream*>(closure);
  out->write(reinterpret_cast<const char*>(data), length);
  return *out ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_WRITE_ERROR;
}

void write_png(std::ostream& out, const formats::Snapshot& snap, const Window& win, double width_px,
               const std::string& it, std::uint32_t layers) {
  const bool walls = layers & turtle::kLayerWalls, balls = layers & turtle::kLayerBalls,
             turtles = layers & turtle::kLayerTurtles, trails = layers & turtle::kLayerTrails,
             roles = layers & turtle::kLayerRoles;
  const Layout l = layout_for(win, width_px);
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, l.width, l.height), cairo_surface_destroy);
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> ctx(cairo_create(surface.get()), cairo_destroy);
  cairo_t* cr = ctx.get();
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);

  // Colours span 0 to the 99th-percentile speed, as in the SVG.
  std::vector<double> speeds;
  speeds.reserve(snap.balls.size());
  for (const auto& b : snap.balls) speeds.push_back(sim::norm(b.vel));
  double v_max = 0.0;
  if (!speeds.empty()) {
    std::vector<double> sorted = speeds;
    const auto k = static_cast<std::ptrdiff_t>((sorted.size() - 1) * 99 / 100);
    std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
    v_max = sorted[static_cast<std::size_t>(k)];
  }
  const double v_scale = v_max > 0.0 ? v_max : 1.0;

  // The title.
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 16);
  set_grey(cr, 0);
  char title[512];
  std::snprintf(title, sizeof title, "%s - t = %.6g s, %zu balls", snap.title.c_str(), snap.time, snap.balls.size());
  std::string text = title;
  if (!snap.turtles.empty())
    text += ", " + std::to_string(snap.turtles.size()) + (snap.turtles.size() == 1 ? " turtle" : " turtles");
  // A title wider than the picture is set smaller until it fits (it was cut at the right edge).
  cairo_text_extents_t ext;
  cairo_text_extents(cr, text.c_str(), &ext);
  const double room = l.width - 2 * l.margin;
  if (ext.x_advance > room && ext.x_advance > 0.0) cairo_set_font_size(cr, std::max(6.0, 16.0 * room / ext.x_advance));
  cairo_move_to(cr, l.margin, l.margin + 14);
  cairo_show_text(cr, text.c_str());

  // The world inside the window: +y up, clipped to the window's rectangle.
  cairo_save(cr);
  cairo_rectangle(cr, l.margin, l.top, win.w * l.scale, win.h * l.scale);
  cairo_clip(cr);
  cairo_translate(cr, l.margin + win.w * l.scale / 2, l.top + win.h * l.scale / 2);
  cairo_scale(cr, l.scale, -l.scale);
  cairo_rotate(cr, win.angle);  // a heading of `angle` points up
  cairo_translate(cr, -win.cx, -win.cy);

  cairo_rectangle(cr, 0, 0, snap.arena.width, snap.arena.height);
  cairo_set_source_rgb(cr, 0xf7 / 255.0, 0xf7 / 255.0, 0xf7 / 255.0);
  cairo_fill_preserve(cr);
  set_grey(cr, 0x99);
  stroke_px(cr, 1);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  for (const auto& wall : snap.walls) {
    if (!walls) break;
    const sim::WallKey pose = sim::wall_pose(wall, snap.time);
    const bool there = sim::wall_visible(wall, snap.time);
    cairo_move_to(cr, pose.from.x, pose.from.y);
    cairo_line_to(cr, pose.to.x, pose.to.y);
    if (there) {
      set_grey(cr, 0x22);
    } else {
      set_grey(cr, 0xbb);
      const double dash[2] = {4, 3};
      cairo_set_dash(cr, dash, 2, 0);
    }
    stroke_px(cr, 2);
    cairo_set_dash(cr, nullptr, 0, 0);
  }
  for (std::size_t i = 0; i < snap.balls.size() && balls; ++i) {
    const auto& b = snap.balls[i];
    cairo_arc(cr, b.pos.x, b.pos.y, b.radius, 0, 2 * M_PI);
    set_rgb(cr, speed_colour(speeds[i] / v_scale));
    cairo_fill(cr);
  }
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  for (std::size_t i = 0; i < snap.turtles.size(); ++i) {
    const auto& t = snap.turtles[i];
    if (t.trail.size() < 2 || !trails) continue;
    bool gap = true;  // a break between strokes (the pen lifted, or a teleport)
    for (const sim::Vec2 p : t.trail) {
      if (turtle::is_trail_break(p)) {
        gap = true;
        continue;
      }
      if (gap) cairo_move_to(cr, p.x, p.y);
      else cairo_line_to(cr, p.x, p.y);
      gap = false;
    }
    set_rgb(cr, turtle_colours[i % turtle_colours.size()]);
    stroke_px(cr, 1.5);
  }
  for (std::size_t i = 0; i < snap.turtles.size() && turtles; ++i) {
    const auto& t = snap.turtles[i];
    if (t.id == it && roles) {  // the tag game's "it": a red ring around it
      cairo_arc(cr, t.pos.x, t.pos.y, t.radius * 1.6, 0, 2 * M_PI);
      cairo_set_source_rgb(cr, 0.85, 0.1, 0.1);
      stroke_px(cr, 3);
    }
    cairo_arc(cr, t.pos.x, t.pos.y, t.radius, 0, 2 * M_PI);
    set_rgb(cr, turtle_colours[i % turtle_colours.size()], 0.8);
    cairo_fill_preserve(cr);
    set_grey(cr, 0x22);
    stroke_px(cr, 1);
    const sim::Vec2 tip = t.pos + t.radius * sim::heading_unit(t.heading);
    cairo_move_to(cr, t.pos.x, t.pos.y);
    cairo_line_to(cr, tip.x, tip.y);
    stroke_px(cr, 2);
    if (t.fault) {
      const double d = t.radius * 0.7;
      cairo_move_to(cr, t.pos.x - d, t.pos.y - d);
      cairo_line_to(cr, t.pos.x + d, t.pos.y + d);
      cairo_move_to(cr, t.pos.x - d, t.pos.y + d);
      cairo_line_to(cr, t.pos.x + d, t.pos.y - d);
      cairo_set_source_rgb(cr, 0.8, 0, 0);
      stroke_px(cr, 2);
    }
  }
  // Ids beside each turtle's upper right, upright.
  cairo_set_font_size(cr, 11 / l.scale);
  for (const auto& t : snap.turtles) {
    if (!turtles) break;
    cairo_save(cr);
    cairo_translate(cr, t.pos.x, t.pos.y);
    cairo_rotate(cr, -win.angle);
    cairo_move_to(cr, t.radius + 2 / l.scale, t.radius);
    cairo_scale(cr, 1, -1);
    set_grey(cr, 0);
    cairo_show_text(cr, t.id.c_str());
    cairo_restore(cr);
  }
  cairo_restore(cr);

  // The legend: a colour bar from 0 (bottom) to v_max (top), when there are balls.
  if (!snap.balls.empty() && balls) {
    const double lx = l.margin + win.w * l.scale + 24.0, ly = l.top + 16.0, lh = 120.0;
    cairo_pattern_t* g = cairo_pattern_create_linear(0, ly + lh, 0, ly);
    for (std::size_t k = 0; k < palette.size(); ++k) {
      const double u = static_cast<double>(k) / (palette.size() - 1);
      const auto c = speed_colour(u);
      cairo_pattern_add_color_stop_rgb(g, u, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
    }
    cairo_rectangle(cr, lx, ly, 14, lh);
    cairo_set_source(cr, g);
    cairo_fill_preserve(cr);
    cairo_pattern_destroy(g);
    set_grey(cr, 0x99);
    cairo_set_line_width(cr, 1);
    cairo_stroke(cr);
    set_grey(cr, 0);
    cairo_set_font_size(cr, 12);
    cairo_move_to(cr, lx - 8, ly - 6);
    cairo_show_text(cr, "speed");
    cairo_set_font_size(cr, 11);
    char vmax[64];
    std::snprintf(vmax, sizeof vmax, ">= %.6g", v_max);
    cairo_move_to(cr, lx + 18, ly + 10);
    cairo_show_text(cr, vmax);
    cairo_move_to(cr, lx + 18, ly + lh);
    cairo_show_text(cr, "0");
  }
  cairo_surface_flush(surface.get());
  if (cairo_surface_write_to_png_stream(surface.get(), write_to_stream, &out) != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error("could not encode the PNG");
}

/// Runs the scene forward and draws it at the times asked for.
class Renderer {
 public:
  Renderer(Source& source, const turtle::Registry& registry, const RenderOptions& opt) : source_(source), opt_(opt) {
    turtle::ServerOptions o;
    o.mode = source.mode;
    server_ = make_server(source.scene, registry, o, opt.input);
  }

  /// Makes the scene stop inside a step too (run_loop.hpp), and paces its chunks by its scales.
  void limit(const Limits& limits, Clock::time_point start) {
    stop_inside_steps(*server_, limits, start);
    pace_ = first_pace(predict_scales(source_.scene.def, source_.mode), server_->world(), source_.scene.def.dt);
  }
  /// Runs the scene to t in chunks, as `run` runs: a stop (a signal, a limit) leaves it short of t.
  Stopped advance_to(double t, const Limits& limits, Clock::time_point start, Progress& progress,
                     const std::string& doing) {
    return run_server_in_chunks(*server_, t, 0, limits, pace_, start, progress, doing);
  }
  double time() const { return server_->time(); }
  /// Warns, with numbers, when running the scene to t predicts a run that will not finish (as run
  /// and check do): `render --at 1e300` otherwise ran for ever without a word.
  void warn_if_absurd(double t, const std::string& span) const {
    SceneScales scales = predict_scales(source_.scene.def, source_.mode);
    scales.set_cell(server_->world().cell_size());
    for (const std::string& w : scale_warnings(scales, t - server_->time(), span))
      spdlog::warn("{}: {}; --max-wall-seconds or --max-events end it cleanly", opt_.input, w);
  }

  /// The whole arena, or what view `opt.view` shows now (a view of the world file's, or one a
  /// program has opened by this time); layers: the view's (turtle/view.hpp).
  Window window(std::uint32_t& layers) const {
    layers = turtle::kLayersAll;
    const sim::ArenaDef& a = source_.scene.def.arena;
    if (opt_.view.empty()) return {a.width / 2, a.height / 2, a.width, a.height, 0.0};
    const std::optional<turtle::View> v = server_->find_view(opt_.view);
    if (!v) {
      std::string open;
      for (const turtle::View& w : server_->views()) open += (open.empty() ? "" : ", ") + w.id;
      throw BadInput("--view " + opt_.view + ": no view with that id is open at t = " + fmt(server_->time()) +
                     " s (open then: " + (open.empty() ? "none" : open) + "; the world file's \"views\" and the ones "
                     "its programs open)");
    }
    std::optional<turtle::FollowPose> pose;
    if (v->follow)
      if (const auto i = server_->turtle_index(*v->follow)) pose = server_->follow_pose(*i);
    const turtle::ViewTransform x = turtle::view_transform(*v, pose);
    layers = v->layers;
    return {x.center.x, x.center.y, x.size.x, x.size.y, std::atan2(x.up.x, x.up.y)};
  }

  formats::Snapshot snapshot() const {
    formats::Snapshot s = formats::snapshot_of(*server_, source_.scene.def);
    if (s.title.empty()) s.title = "turtlegas";
    if (!opt_.view.empty()) {  // the view's title, as the viewer shows it
      const std::optional<turtle::View> v = server_->find_view(opt_.view);
      if (v) s.title = v->title.empty() ? v->id : v->title;
    }
    return s;
  }

  std::string it() const {
    if (!server_->game()) return {};
    const nlohmann::json s = server_->game()->score(server_->time());
    return s.contains("it") && s.at("it").is_string() ? s.at("it").get<std::string>() : std::string();
  }

  void draw(const std::string& path, const std::string& option) {
    OutputFile out(path, option);
    const formats::Snapshot snap = snapshot();
    if (path.size() >= 4 && path.substr(path.size() - 4) == ".svg") {
      if (!opt_.view.empty())
        throw BadInput("--view goes with PNG pictures and frames; the SVG is of the whole arena (use --out F.png)");
      formats::write_svg(out.stream(), snap, opt_.width);
    }
    else {
      std::uint32_t layers = 0;
      const Window win = window(layers);
      write_png(out.stream(), snap, win, opt_.width, it(), layers);
    }
    out.commit();
  }

 private:
  Source& source_;
  const RenderOptions& opt_;
  std::unique_ptr<turtle::WorldServer> server_;
  Pace pace_;
};

std::string find_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::string p = path ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= p.size()) {
    const std::size_t end = std::min(p.find(':', start), p.size());
    const fs::path candidate = fs::path(p.substr(start, end - start).empty() ? "." : p.substr(start, end - start)) / program;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    start = end + 1;
  }
  return {};
}

/// "frame-00042.png"
std::string frame_name(std::size_t k) {
  char name[32];
  std::snprintf(name, sizeof name, "frame-%05zu.png", k);
  return name;
}

bool ends_with(const std::string& s, const std::string& e) { return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0; }

}  // namespace

CLI::App* add_render_command(CLI::App& app, RenderOptions& opt) {
  constexpr double big = std::numeric_limits<double>::max();
  CLI::App* r = app.add_subcommand("render", "Draw a world or a recording at a time (SVG, PNG), as frames, or as a video");
  r->add_option("input", opt.input, "A world file (turtlegas-world/1) or a recording (run --record)")->required();
  r->add_option("--at", opt.at, "Draw the scene at this simulated time, seconds")->check(real_in(0, big, "seconds"));
  r->add_option("--out", opt.out, "The picture: a .svg or .png file (with --at)");
  r->add_option("--frames", opt.frames, "Write frame-00000.png, ... into this directory (created if missing)");
  r->add_option("--video", opt.video, "Encode the frames into this .mp4 (needs ffmpeg)");
  r->add_option("--fps", opt.fps, "Frames per simulated second")->capture_default_str()->check(real_in(0, 1000, "frames/s", true));
  r->add_option("--from", opt.from, "The first frame's time (default 0)")->check(real_in(0, big, "seconds"));
  r->add_option("--to", opt.to, "The last frame's time (default: the recording's end; needed for a world file)")
      ->check(real_in(0, big, "seconds"));
  r->add_option("--width", opt.width, "Pixels across the arena's longer side")->capture_default_str()->check(real_in(16, 8192, "pixels"));
  r->add_option("--view", opt.view, "Draw what this view of the world shows (its \"views\")");
  opt.limits.add_to(*r, "the rendering", "the frames drawn so far kept");
  return r;
}

int render_command(const RenderOptions& opt, const turtle::Registry& registry) {
  const auto start = Clock::now();
  const bool one = opt.at.has_value();
  const bool many = !opt.frames.empty() || !opt.video.empty();
  if (one == many)
    throw BadInput(one ? "render: --at draws one picture, --frames/--video a sequence; give one or the other"
                       : "render: say what to draw: --at T --out F.png, or --frames DIR (and/or --video F.mp4) --from T0 --to T1");
  if (one && opt.out.empty()) throw BadInput("render --at " + fmt(*opt.at) + ": --out F.svg or F.png names the picture");
  if (one && !ends_with(opt.out, ".svg") && !ends_with(opt.out, ".png"))
    throw BadInput("--out " + opt.out + ": the picture's name must end in .svg or .png");
  if (!opt.out.empty() && !one) throw BadInput("--out goes with --at; a sequence goes to --frames DIR or --video F.mp4");
  std::string ffmpeg;
  if (!opt.video.empty()) {
    if (!ends_with(opt.video, ".mp4")) throw BadInput("--video " + opt.video + ": the video's name must end in .mp4");
    ffmpeg = find_on_path("ffmpeg");
    if (ffmpeg.empty())
      throw BadInput("--video needs ffmpeg, which is not installed (Debian: apt-get install ffmpeg); --frames DIR "
                     "writes the PNG frames without it");
  }
  check_outputs({{opt.out, "--out"}, {opt.video, "--video"}}, {{opt.input, "the input"}});
  if (!opt.out.empty()) OutputFile probe(opt.out, "--out");  // a bad path costs nothing
  if (!opt.video.empty()) OutputFile probe(opt.video, "--video");

  Source source = load_source(opt.input, registry);
  auto within = [&](double t, const char* what) {
    if (source.end && t > *source.end)
      throw BadInput(std::string(what) + " " + fmt(t) + ": the recording " + opt.input + " ends at t = " + fmt(*source.end) +
                     " s");
  };
  Renderer renderer(source, registry, opt);
  install_stop_signals();
  install_crash_report(opt.input);
  Limits limits;
  limits.max_wall_seconds = opt.limits.wall_seconds();
  limits.max_events = opt.limits.events();
  renderer.limit(limits, start);
  // A stop before the picture asked for: nothing is drawn, and the message says how far it got.
  auto stopped = [&](Stopped end, const std::string& what) {
    spdlog::warn("{}: stopped at t = {} s ({}); {}", opt.input, fmt(renderer.time()), stop_name(end), what);
    return exit_code_for(end);
  };
  {
    if (one) {
      within(*opt.at, "--at");
      renderer.warn_if_absurd(*opt.at, "drawing at --at " + fmt(*opt.at));
      Progress progress(*opt.at);
      const Stopped end = renderer.advance_to(*opt.at, limits, start, progress, "drawing at --at: ");
      progress.clear();
      if (end.first != Stop::until)
        return stopped(end, "the picture at --at " + fmt(*opt.at) + " is not drawn (--out " + opt.out + " untouched)");
      renderer.draw(opt.out, "--out");
      return exit_ok;
    }
    const double t0 = opt.from.value_or(0.0);
    if (!opt.to && !source.end) throw BadInput("--frames/--video of a world file: --to T1 says when the frames end");
    const double t1 = opt.to.value_or(source.end.value_or(0.0));
    within(t1, "--to");
    if (!(t1 >= t0)) throw BadInput("--to " + fmt(t1) + " must not be before --from " + fmt(t0));
    // Frame k at t0 + k / fps, k = 0 .. floor(fps (t1 - t0)) (the last at or just before t1; the
    // tolerance keeps a span of whole frames from losing its last one to rounding).
    // Counted in double first: `--to 1e300` made the cast to an integer overflow (undefined; it drew
    // one frame and said nothing).
    const double frames = std::floor((t1 - t0) * opt.fps * (1 + 1e-12) + 1e-9) + 1;
    if (!(frames <= 1000000))
      throw BadInput("render: " + fmt(frames) + " frames is too many (at most 1000000); narrow --from/--to or lower --fps");
    const auto count = static_cast<std::size_t>(frames);
    renderer.warn_if_absurd(t1, "frames to --to " + fmt(t1));
    fs::path dir = opt.frames;
    const bool temporary = dir.empty();
    if (temporary) dir = fs::temp_directory_path() / ("turtlegas-frames-" + std::to_string(::getpid()));
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir)) throw BadInput("--frames " + dir.string() + ": cannot make that directory");
    Progress progress(t1);
    progress.set_part(t1, -t0, t1 - t0);
    for (std::size_t k = 0; k < count; ++k) {
      const double t = t0 + static_cast<double>(k) / opt.fps;
      const std::string doing = "frame " + std::to_string(k + 1) + " of " + std::to_string(count) + ": ";
      const Stopped end = renderer.advance_to(t, limits, start, progress, doing);
      if (end.first != Stop::until) {
        progress.clear();
        if (temporary) fs::remove_all(dir, ec);
        std::string kept = "no frames are kept";
        if (!opt.frames.empty() && k > 0)
          kept = "frame-00000.png to " + frame_name(k - 1) + " in " + dir.string() + " are whole";
        else if (!opt.frames.empty())
          kept = "no frame was drawn";
        return stopped(end, "before " + frame_name(k) + ", " + std::to_string(k + 1) + " of " + std::to_string(count) +
                                " (t = " + fmt(t) + " s); " + kept + (opt.video.empty() ? "" : "; --video " + opt.video + " is not made"));
      }
      renderer.draw((dir / frame_name(k)).string(), "--frames");
    }
    progress.clear();
    if (!opt.frames.empty()) spdlog::info("{} frames, t = {} to {} s, in {}", count, fmt(t0), fmt(t0 + (count - 1) / opt.fps), dir.string());
    if (!opt.video.empty()) {
      const fs::path target = opt.video;
      const fs::path tmp = target.parent_path() / ("." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) + ".mp4");
      char rate[32];
      std::snprintf(rate, sizeof rate, "%.10g", opt.fps);
      std::vector<std::string> args = {ffmpeg, "-loglevel", "error", "-y", "-framerate", rate, "-i", (dir / "frame-%05d.png").string(),
                                        "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", tmp.string()};
      std::vector<char*> argv;
      argv.reserve(args.size() + 1);  // and the closing null
      for (std::string& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      pid_t pid = 0;
      int status = 0;
      const int rc = ::posix_spawn(&pid, ffmpeg.c_str(), nullptr, nullptr, argv.data(), environ);
      if (rc != 0 || ::waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        fs::remove(tmp, ec);
        if (temporary) fs::remove_all(dir, ec);
        throw std::runtime_error("--video " + opt.video + ": ffmpeg failed (its messages are above)");
      }
      fs::rename(tmp, target, ec);
      if (temporary) fs::remove_all(dir, ec);
      if (ec) throw std::runtime_error("--video: could not put '" + opt.video + "' in place: " + ec.message());
    }
  }
  return exit_ok;
}

}  // namespace turtlegas::apps
