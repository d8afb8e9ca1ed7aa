// SPDX-License-Identifier: MIT
#include "render_command.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <spdlog/spdlog.h>

#include "cairo_frame.hpp"
#include "run3d.hpp"
#include "cli_common.hpp"
#include "output_file.hpp"
#include "run_loop.hpp"
#include "scene_scales.hpp"
#include "signals.hpp"
#include "turtlegas/formats/recording.hpp"
#include "turtlegas/formats/svg_snapshot.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/turtle/game.hpp"
#include "turtlegas/turtle/program_log.hpp"
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
  std::string recording;                  ///< a recording: its path
  std::vector<formats::Keyframe> keyframes;  ///< a recording: its keyframes, checked as the run passes them
};

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
  s.recording = path;
  s.keyframes = std::move(rec.keyframes);
  return s;
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
  /// A recording's keyframes on the way are reached exactly and compared with the run (cutting a
  /// run does not change it); the first difference is warned about, once.
  Stopped advance_to(double t, const Limits& limits, Clock::time_point start, Progress& progress,
                     const std::string& doing) {
    while (next_key_ < source_.keyframes.size() && source_.keyframes[next_key_].t <= t) {
      const formats::Keyframe& k = source_.keyframes[next_key_];
      if (k.t > server_->time()) {
        const Stopped end = run_server_in_chunks(*server_, k.t, 0, limits, pace_, start, progress, doing);
        if (end.first != Stop::until) return end;
      }
      ++next_key_;
      if (k.t == server_->time()) check_keyframe(k);
    }
    return run_server_in_chunks(*server_, t, 0, limits, pace_, start, progress, doing);
  }
  double time() const { return server_->time(); }
  /// Compares the run with keyframe `k` of the recording (the run is at its time); warns once.
  void check_keyframe(const formats::Keyframe& k) {
    if (diverged_) return;
    const formats::IdTable ids = formats::ball_ids(server_->scene());
    const std::optional<std::string> d =
        formats::keyframe_difference(formats::read_keyframe(source_.recording, k), server_->world(),
                                     formats::RunNames{ids, server_->scene(), server_->world()});
    if (!d) return;
    diverged_ = true;
    spdlog::warn("{}: at t = {} s this run differs from the recording's keyframe ({}): the recorded world, a program, "
                 "or this build differs from the one that recorded it, and the pictures from here on show this run, "
                 "not the recorded one",
                 source_.recording, fmt(k.t), *d);
  }
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
      try {
        write_png(out.stream(), snap, win, opt_.width, it(), layers);
      } catch (const std::runtime_error& e) {
        const std::string why = out.failure();  // "No space left on device"
        throw std::runtime_error(option + " " + path + ": " + e.what() + (why.empty() ? "" : ": " + why));
      }
    }
    out.commit();  // says why a write failed (a full disk), naming the file
  }

 private:
  Source& source_;
  const RenderOptions& opt_;
  std::unique_ptr<turtle::WorldServer> server_;
  Pace pace_;
  std::size_t next_key_ = 0;  ///< the recording's first keyframe not yet reached
  bool diverged_ = false;     ///< a keyframe differed (warned about)
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
  r->add_flag("--program-logs", opt.program_logs,
              "Print the turtle programs' log lines as the world is run again to draw it (off: the run printed them)");
  r->add_option("--view", opt.view, "Draw what this view of the world shows (its \"views\")");
  opt.limits.add_to(*r, "the rendering", "the frames drawn so far kept");
  return r;
}

int render_command(const RenderOptions& opt, const turtle::Registry& registry) {
  const auto start = Clock::now();
  turtle::set_program_logs(opt.program_logs);
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

  if (const auto w3 = load_world3_if_3d(opt.input)) {
    if (!one) throw BadInput("render of a 3-D world draws one picture: --at T --out F.svg or F.png (no frames or video yet)");
    return render3d(opt.input, *opt.at, opt.out, opt.width, *w3);
  }
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
                                        "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2:color=white", "-pix_fmt", "yuv420p", tmp.string()};
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
