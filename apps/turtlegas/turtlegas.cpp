// SPDX-License-Identifier: MIT
// The turtlegas command-line program: `turtlegas run`, `turtlegas check` and `turtlegas controllers`
// (see docs/design.md, "Command line", for the contract this file keeps). A scene with turtles runs
// through the world server (their programs between control steps); one without runs the bare engine.
#include <dlfcn.h>
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>  // mallopt
#endif

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "tag_command.hpp"
#include "test_command.hpp"
#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/formats/svg_snapshot.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/turtle/game.hpp"
#include "turtlegas/turtle/world_server.hpp"
#include "turtlegas/world/scene.hpp"
#include "turtlegas/world/world_file.hpp"

namespace {

namespace fs = std::filesystem;
namespace sim = turtlegas::sim;
namespace tw = turtlegas::world;
namespace tf = turtlegas::formats;
namespace tt = turtlegas::turtle;
using Clock = std::chrono::steady_clock;

constexpr int exit_ok = 0;
constexpr int exit_failure = 1;
constexpr int exit_bad_input = 2;

/// A problem with the command line or the world file: exit code 2.
struct BadInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Shortest decimal that reads back as the same double (at most 17 significant digits).
void append_number(std::string& out, double v) {
  std::array<char, 32> buf{};
  auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  out.append(buf.data(), r.ptr);
}

void append_json_string(std::string& out, std::string_view s) {
  out += '"';
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          std::array<char, 8> buf{};
          std::snprintf(buf.data(), buf.size(), "\\u%04x", static_cast<unsigned>(c));
          out += buf.data();
        } else {
          out += c;
        }
    }
  }
  out += '"';
}

/// An output file written under a temporary name in the same directory and renamed over the
/// target only by commit(), so a failed or interrupted run never leaves a file that looks whole.
class AtomicFile {
 public:
  AtomicFile(fs::path target, std::string_view option) : target_(std::move(target)) {
    const fs::path dir = target_.parent_path().empty() ? fs::path(".") : target_.parent_path();
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
      throw BadInput(std::string(option) + ": directory '" + dir.string() + "' does not exist; create it first");
    if (fs::is_directory(target_, ec))
      throw BadInput(std::string(option) + ": '" + target_.string() + "' is a directory; give a file name");
    tmp_ = dir / ("." + target_.filename().string() + ".tmp-" + std::to_string(::getpid()));
    out_.open(tmp_, std::ios::binary | std::ios::trunc);
    if (!out_) throw BadInput(std::string(option) + ": cannot write in '" + dir.string() + "'; check its permissions");
  }
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile() {
    if (committed_) return;
    out_.close();
    std::error_code ec;
    fs::remove(tmp_, ec);
  }

  std::ofstream& stream() { return out_; }

  void commit() {
    out_.close();
    if (out_.fail()) throw std::runtime_error("could not finish writing '" + target_.string() + "' (disk full?)");
    fs::rename(tmp_, target_);
    committed_ = true;
  }

 private:
  fs::path target_;
  fs::path tmp_;
  std::ofstream out_;
  bool committed_ = false;
};

struct RunOptions {
  std::string world;
  double until = 0.0;
  std::string mode = "exact";
  std::optional<double> dt;
  std::string events, state_out, stats_json, svg;
  bool stats = false;
  std::size_t stack_kib = 32;   ///< each turtle program's stack
  double program_budget = 2.0;  ///< wall-clock seconds a program may run without a command
};

/// Ball ids packed into one buffer (a std::string each would cost 32 bytes a ball, more than
/// the engine's whole per-ball budget allows beside it).
class IdTable {
 public:
  void reserve(std::size_t ids, std::size_t chars) {
    end_.reserve(ids);
    chars_.reserve(chars);
  }
  void push_back(std::string_view id) {
    chars_.append(id);
    end_.push_back(chars_.size());
  }
  std::string_view operator[](std::size_t i) const {
    const std::size_t begin = i == 0 ? 0 : end_[i - 1];
    return std::string_view(chars_).substr(begin, end_[i] - begin);
  }

 private:
  std::string chars_;
  std::vector<std::size_t> end_;
};

/// The event log as JSON lines, written in chunks while the world runs. Ball ids come apart from
/// the scene, which the World may have taken over (World(WorldDef&&)).
class EventWriter {
 public:
  EventWriter(AtomicFile& file, const IdTable& ball_ids, const sim::WorldDef& def, const sim::World& world)
      : file_(file), ball_ids_(ball_ids), def_(def), world_(world) {}

  void write(const std::vector<sim::Event>& events) {
    buf_.clear();
    for (const sim::Event& e : events) {
      buf_ += "{\"t\": ";
      append_number(buf_, e.t);
      buf_ += ", \"kind\": \"";
      buf_ += sim::to_string(e.kind);
      buf_ += "\", \"a\": ";
      const bool turtle_a = sim::involves_turtle(e.kind) || (e.kind == sim::EventKind::exit && e.b == 1);
      append_json_string(buf_, turtle_a ? std::string_view(def_.turtles[e.a].id) : ball_ids_[e.a]);
      std::optional<std::string_view> b;
      switch (e.kind) {
        case sim::EventKind::ball_ball:
        case sim::EventKind::turtle_ball: b = ball_ids_[e.b]; break;
        case sim::EventKind::ball_wall:
        case sim::EventKind::ball_wall_end:
        case sim::EventKind::turtle_wall:
        case sim::EventKind::turtle_wall_end: b = world_.walls()[e.b].id; break;
        case sim::EventKind::turtle_turtle: b = def_.turtles[e.b].id; break;
        case sim::EventKind::exit: break;  // b only says what kind of body left
      }
      if (b) {
        buf_ += ", \"b\": ";
        append_json_string(buf_, *b);
      }
      buf_ += "}\n";
    }
    file_.stream().write(buf_.data(), static_cast<std::streamsize>(buf_.size()));
  }

 private:
  AtomicFile& file_;
  const IdTable& ball_ids_;
  const sim::WorldDef& def_;
  const sim::World& world_;
  std::string buf_;
};

/// The world server's event log (balls' and turtles' events, touches, faults) as JSON lines.
class LogEventWriter {
 public:
  explicit LogEventWriter(AtomicFile& file) : file_(file) {}

  void write(const std::vector<tt::LogEvent>& events) {
    buf_.clear();
    for (const tt::LogEvent& e : events) {
      buf_ += "{\"t\": ";
      append_number(buf_, e.t);
      buf_ += ", \"kind\": ";
      append_json_string(buf_, e.kind);
      buf_ += ", \"a\": ";
      append_json_string(buf_, e.a);
      if (!e.b.empty()) {  // an exit or a fault names no second body
        buf_ += ", \"b\": ";
        append_json_string(buf_, e.b);
      }
      if (e.kind == "touch") {
        buf_ += ", \"sensors\": [";
        for (std::size_t k = 0; k < e.sensors.size(); ++k) {
          if (k > 0) buf_ += ", ";
          append_json_string(buf_, e.sensors[k]);
        }
        // Degrees clockwise from the heading to the contact point, [0, 360).
        buf_ += "], \"bearing\": ";
        append_number(buf_, e.bearing);
      }
      if (!e.message.empty()) {
        buf_ += ", \"message\": ";
        append_json_string(buf_, e.message);
      }
      buf_ += "}\n";
    }
    file_.stream().write(buf_.data(), static_cast<std::streamsize>(buf_.size()));
  }

 private:
  AtomicFile& file_;
  std::string buf_;
};

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

tw::Scene load(const std::string& file, const tt::Registry& registry) {
  try {
    return tw::load_scene(file, registry);
  } catch (const tw::WorldFileError& e) {
    throw BadInput(e.what());
  }
}

/// As make_world, for a scene with turtles: the server also checks controllers and sensors.
std::unique_ptr<tt::WorldServer> make_server(const tw::Scene& scene, const tt::Registry& registry,
                                             const tt::ServerOptions& options, const std::string& file) {
  try {
    return tw::make_server(scene, registry, options);  // with the scene's game (scene.hpp)
  } catch (const std::invalid_argument& e) {
    throw BadInput(file + ": " + std::string(sim::to_string(options.mode)) + " mode: " + e.what());
  }
}

/// The engine rejects a scene it cannot run (a cell size against the memo's rule, say) with
/// std::invalid_argument: that is the world file's fault, so exit code 2.
template <class Def>  // const sim::WorldDef& or sim::WorldDef&&
sim::World make_world(Def&& def, sim::Mode mode, const std::string& file) {
  try {
    return sim::World(std::forward<Def>(def), mode);
  } catch (const std::invalid_argument& e) {
    throw BadInput(file + ": " + std::string(sim::to_string(mode)) + " mode: " + e.what());
  }
}

std::string count_summary(const sim::WorldDef& def, std::size_t balls) {
  auto plural = [](std::size_t n, const char* noun) { return std::to_string(n) + " " + noun + (n == 1 ? "" : "s"); };
  std::string s = plural(balls, "ball") + ", " + plural(def.walls.size(), "wall");
  if (def.arena.boundary == sim::Boundary::walls) s += " (+4 arena walls)";
  if (!def.turtles.empty()) s += ", " + plural(def.turtles.size(), "turtle");
  return s;
}

const char* boundary_name(sim::Boundary b) {
  switch (b) {
    case sim::Boundary::none: return "none";
    case sim::Boundary::walls: return "walls";
    case sim::Boundary::periodic: return "periodic";
  }
  return "?";
}

std::string fmt(double v) {
  std::array<char, 32> buf{};
  std::snprintf(buf.data(), buf.size(), "%.6g", v);
  return buf.data();
}

/// "wander x3, script": each controller the scene uses and how many turtles run it, in file order.
std::string controller_summary(const tw::Scene& scene) {
  std::vector<std::pair<std::string, std::size_t>> uses;
  for (const tt::TurtleProgram& p : scene.programs) {
    auto it = std::find_if(uses.begin(), uses.end(), [&](const auto& u) { return u.first == p.controller; });
    if (it == uses.end()) uses.emplace_back(p.controller, 1);
    else ++it->second;
  }
  std::string s;
  for (const auto& [name, n] : uses) s += (s.empty() ? "" : ", ") + name + (n > 1 ? " x" + std::to_string(n) : "");
  return s;
}

int check_command(const std::string& file, const tt::Registry& registry) {
  const tw::Scene scene = load(file, registry);
  const sim::WorldDef& def = scene.def;
  const sim::World exact = make_world(def, sim::Mode::exact, file);
  const sim::World step = make_world(def, sim::Mode::step, file);
  std::printf("%s: ok: \"%s\", %s, arena %s x %s (boundary %s), cell %s (%d x %d), dt %s s\n", file.c_str(),
              def.name.c_str(), count_summary(def, def.balls.size()).c_str(), fmt(def.arena.width).c_str(), fmt(def.arena.height).c_str(),
              boundary_name(def.arena.boundary), fmt(step.cell_size()).c_str(), step.cells_x(), step.cells_y(),
              fmt(def.dt).c_str());
  if (!def.turtles.empty()) {
    // Building the servers checks what only the runtime knows (controllers, sensors); no program
    // runs until the first control step, so this costs nothing.
    for (sim::Mode mode : {sim::Mode::exact, sim::Mode::step}) {
      tt::ServerOptions options;
      options.mode = mode;
      make_server(scene, registry, options, file);
    }
    std::printf("  turtles: %s; controllers: %s\n",
                [&] {
                  std::string ids;
                  constexpr std::size_t shown = 8;
                  for (std::size_t i = 0; i < def.turtles.size() && i < shown; ++i)
                    ids += (i ? ", " : "") + def.turtles[i].id;
                  if (def.turtles.size() > shown) ids += ", ... (" + std::to_string(def.turtles.size()) + " in all)";
                  return ids;
                }()
                    .c_str(),
                controller_summary(scene).c_str());
  }
  return exit_ok;
}

/// Loads controller plugins: shared modules exporting `extern "C" void turtlegas_register(Registry&)`,
/// built against the same turtlegas headers and compiler (see docs/controllers.md). They stay loaded
/// for the life of the program, since the registry holds their code.
void load_plugins(const std::vector<std::string>& paths, tt::Registry& registry) {
  using Register = void (*)(tt::Registry&);
  for (const std::string& path : paths) {
    // A bare name would be searched for on the library path; a plugin is a file the user names.
    const std::string file = path.find('/') == std::string::npos ? "./" + path : path;
    void* handle = ::dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = ::dlerror();
      throw BadInput("--plugin " + path + ": cannot load it: " + (why ? why : "unknown error") +
                     " (is it a plugin built with turtlegas_add_plugin, for this turtlegas?)");
    }
    auto* entry = reinterpret_cast<Register>(::dlsym(handle, "turtlegas_register"));
    if (!entry)
      throw BadInput("--plugin " + path +
                     ": it does not export turtlegas_register; define extern \"C\" void "
                     "turtlegas_register(turtlegas::turtle::Registry&) in it");
    entry(registry);
  }
}

int controllers_command(const tt::Registry& registry) {
  std::size_t width = 0;
  for (const std::string& name : registry.names()) width = std::max(width, name.size());
  for (const std::string& name : registry.names())
    std::printf("%-*s  %s\n", static_cast<int>(width), name.c_str(), registry.summary(name).c_str());
  return exit_ok;
}

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

void write_state(AtomicFile& file, const sim::World& world, const IdTable& ball_ids,
                 const sim::WorldDef& def) {
  std::string buf = "{\"t\": ";
  append_number(buf, world.time());
  buf += ", \"balls\": [";
  bool first = true;
  for (std::size_t i = 0; i < world.ball_count(); ++i) {
    const sim::BallState b = world.ball(i);
    if (!b.alive) continue;
    buf += first ? "\n  " : ",\n  ";
    first = false;
    buf += "{\"id\": ";
    append_json_string(buf, ball_ids[i]);
    buf += ", \"pos\": [";
    append_number(buf, b.pos.x);
    buf += ", ";
    append_number(buf, b.pos.y);
    buf += "], \"vel\": [";
    append_number(buf, b.vel.x);
    buf += ", ";
    append_number(buf, b.vel.y);
    buf += "]}";
    if (buf.size() > (1u << 20)) {
      file.stream() << buf;
      buf.clear();
    }
  }
  buf += first ? "], \"turtles\": [" : "\n], \"turtles\": [";
  for (std::size_t i = 0; i < world.turtle_count(); ++i) {
    const sim::TurtleState tu = world.turtle(i);
    buf += i == 0 ? "\n  " : ",\n  ";
    buf += "{\"id\": ";
    append_json_string(buf, def.turtles[i].id);
    buf += ", \"pos\": [";
    append_number(buf, tu.pos.x);
    buf += ", ";
    append_number(buf, tu.pos.y);
    // Radians inside, degrees in files (Logo convention: 0 is +y, clockwise), in [0, 360).
    const double heading = sim::wrap_heading_degrees(sim::file_degrees(tu.heading));
    buf += "], \"heading\": ";
    append_number(buf, heading);
    buf += "}";
  }
  buf += world.turtle_count() == 0 ? "]}\n" : "\n]}\n";
  file.stream() << buf;
  file.commit();
}

int run_command(const RunOptions& opt, const tt::Registry& registry) {
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

  tw::Scene scene = load(opt.world, registry);
  sim::WorldDef& def = scene.def;
  if (opt.dt) def.dt = *opt.dt;
  const std::size_t ball_count = def.balls.size();
  IdTable ball_ids;  // for the event log and the state file
  std::size_t id_chars = 0;
  for (const sim::BallDef& b : def.balls) id_chars += b.id.size();
  ball_ids.reserve(ball_count, id_chars);

  Progress progress(opt.until);
  RunTotals totals;
  // Exactly one of these runs the scene: the bare engine, or the world server when there are
  // turtles (which then owns the engine).
  std::optional<sim::World> bare;
  std::unique_ptr<tt::WorldServer> server;
  if (def.turtles.empty()) {
    // The World takes the balls over, so that the scene's copy of them (and their ids' strings)
    // and the engine are never in memory together: a million balls then cost about 170 bytes each
    // rather than 260. def keeps everything else.
    for (const sim::BallDef& b : def.balls) ball_ids.push_back(b.id);
    // (the ids' own strings go with the balls)
    std::vector<sim::BallDef> balls = std::move(def.balls);
    def.balls.clear();
    sim::WorldDef given = def;  // everything but the balls: small
    given.balls = std::move(balls);
    bare.emplace(make_world(std::move(given), mode, opt.world));
    sim::World& world = *bare;
    totals.energy_start = world.energy();
    std::vector<sim::Event> events;
    std::optional<EventWriter> writer;
    if (events_file) {
      writer.emplace(*events_file, ball_ids, def, world);
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
          if (writer) writer->write(events);
          events.clear();
        });
    world.set_event_log(nullptr);
  } else {
    for (const sim::BallDef& b : def.balls) ball_ids.push_back(b.id);
    tt::ServerOptions options;
    options.mode = mode;
    options.stack_bytes = opt.stack_kib * 1024;
    options.program_budget = opt.program_budget;
    server = make_server(scene, registry, options, opt.world);
    totals.energy_start = server->world().energy();
    // The log is always kept: touches and faults are counted from it.
    std::vector<tt::LogEvent> events;
    std::optional<LogEventWriter> writer;
    if (events_file) writer.emplace(*events_file);
    server->set_event_log(&events);
    // Whole control steps at first; programs run only at step boundaries anyway.
    totals.wall_seconds = run_in_chunks(
        server->time(), opt.until, def.dt, def.dt, progress,
        [&](double t) {
          server->run_until(t);  // a BusyLoopError ends the run (exit 1)
          return std::pair{events.size(), server->world().stats().events};
        },
        [&] {
          for (const tt::LogEvent& e : events) {
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

  const sim::Stats& st = world.stats();
  const sim::Overlap now = world.measure_overlap(), seen = world.max_contact_overlap();
  const double max_overlap = std::max(now.depth, seen.depth);
  const double max_overlap_relative = std::max(now.relative, seen.relative);
  const double energy_start = totals.energy_start, energy_end = world.energy();
  const double wall_seconds = totals.wall_seconds;
  std::size_t live = 0;
  for (std::size_t i = 0; i < world.ball_count(); ++i) live += world.ball(i).alive ? 1 : 0;

  if (events_file) events_file->commit();
  if (state_file) write_state(*state_file, world, ball_ids, def);

  const char* mode_name = sim::to_string(mode).data();
  const double per_second = wall_seconds > 0.0 ? static_cast<double>(st.collisions()) / wall_seconds : 0.0;
  if (stats_file) {
    const nlohmann::json j = {
        {"world", opt.world},
        {"name", def.name},
        {"mode", mode_name},
        {"until", opt.until},
        {"dt", def.dt},
        {"seed", def.seed},
        {"balls", ball_count},
        {"balls_alive", live},
        {"walls", world.walls().size()},
        {"turtles", def.turtles.size()},
        {"turtles_finished", totals.turtles_finished},
        {"cell_size", world.cell_size()},
        {"collisions", st.collisions()},
        {"ball_ball", st.ball_ball},
        {"ball_wall", st.ball_wall},
        {"ball_wall_end", st.ball_wall_end},
        {"exits", st.exits},
        {"turtle_wall", st.turtle_wall},
        {"turtle_wall_end", st.turtle_wall_end},
        {"turtle_turtle", st.turtle_turtle},
        {"turtle_ball", st.turtle_ball},
        {"touches", totals.touches},
        {"faults", totals.faults},
        {"cell_crossings", st.cell_crossings},
        {"stale", st.stale},
        {"steps", st.steps},
        {"events", st.events},
        {"wall_seconds", wall_seconds},
        {"collisions_per_second", per_second},
        {"energy_start", energy_start},
        {"energy_end", energy_end},
        {"max_overlap", max_overlap},
        {"max_overlap_relative", max_overlap_relative},
    };
    stats_file->stream() << j.dump(2) << '\n';
    stats_file->commit();
  }

  if (svg_file) {
    tf::write_svg(svg_file->stream(), server ? tf::snapshot_of(*server, def) : tf::snapshot_of(world, def));
    svg_file->commit();
  }

  if (opt.stats) {
    using ull = unsigned long long;
    const double de = energy_start != 0.0 ? (energy_end - energy_start) / std::abs(energy_start) : energy_end - energy_start;
    std::printf("%s (%s): %s, %s mode, t = 0 -> %s s\n", def.name.c_str(), opt.world.c_str(), count_summary(def, ball_count).c_str(),
                mode_name, fmt(world.time()).c_str());
    std::printf("  collisions   %llu  (ball-ball %llu, ball-wall %llu, ball-wall-end %llu)\n", ull(st.collisions()),
                ull(st.ball_ball), ull(st.ball_wall), ull(st.ball_wall_end));
    if (!def.turtles.empty()) {
      std::printf("  turtles      %zu  (turtle-wall %llu, turtle-wall-end %llu, turtle-turtle %llu, turtle-ball %llu)\n",
                  def.turtles.size(), ull(st.turtle_wall), ull(st.turtle_wall_end), ull(st.turtle_turtle),
                  ull(st.turtle_ball));
      std::printf("  programs     %s  (touches %llu, faults %llu, finished %zu)\n", controller_summary(scene).c_str(),
                  ull(totals.touches), ull(totals.faults), totals.turtles_finished);
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
    std::printf("  exits        %llu  (%zu balls left)\n", ull(st.exits), live);
    std::printf("  events       %llu  (cell crossings %llu, stale %llu, steps %llu)\n", ull(st.events),
                ull(st.cell_crossings), ull(st.stale), ull(st.steps));
    std::printf("  wall time    %.3f s  (%s collisions/s)\n", wall_seconds, fmt(per_second).c_str());
    std::printf("  energy       %s -> %s  (relative change %.3g)\n", fmt(energy_start).c_str(), fmt(energy_end).c_str(), de);
    std::printf("  max overlap  %s  (%.3g of a radius)\n", fmt(max_overlap).c_str(), max_overlap_relative);
  }
  return exit_ok;
}

}  // namespace

int main(int argc, char** argv) {
#if defined(__GLIBC__)
  // Arrays above 128 KiB come from mmap and go back to the system when freed. glibc otherwise
  // raises this threshold after the first large free, and the loader's freed arrays would stay
  // resident as holes in the heap under the engine's (see docs/performance.md, "Memory").
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
#endif
  auto log = spdlog::stderr_color_st("turtlegas");
  log->set_pattern("%^%l%$: %v");
  spdlog::set_default_logger(log);

  CLI::App app{"turtlegas: a 2-D gas of discs and walls, and turtles with touch sensors (after MIT AI Memo 272)"};
  app.require_subcommand(1);

  RunOptions opt;
  CLI::App* run = app.add_subcommand("run", "Simulate a world file until time T");
  run->add_option("world", opt.world, "World file (format turtlegas-world/1)")->required();
  run->add_option("--until", opt.until, "Simulated time to stop at, seconds")->required();
  run->add_option("--mode", opt.mode, "exact (event-driven) or step (the memo's fixed steps)")
      ->check(CLI::IsMember(sim::mode_names))
      ->capture_default_str();
  double dt = 0.0;
  CLI::Option* dt_option = run->add_option("--dt", dt, "Step in seconds (overrides the world file's dt)");
  run->add_option("--events", opt.events, "Write the event log here (JSON lines)");
  run->add_option("--state-out", opt.state_out, "Write the final state here (JSON)");
  run->add_flag("--stats", opt.stats, "Print a summary of the run");
  run->add_option("--stats-json", opt.stats_json, "Write the run's statistics here (JSON)");
  run->add_option("--svg", opt.svg, "Write an SVG picture of the final state here");
  std::vector<std::string> plugins;
  const char* plugin_help = "Load controllers from this shared-library plugin (repeatable)";
  run->add_option("--plugin", plugins, plugin_help);
  run->add_option("--stack-kib", opt.stack_kib, "Each turtle program's stack, KiB (a guard page is added)")
      ->capture_default_str();
  run->add_option("--program-budget", opt.program_budget,
                  "Wall-clock seconds a turtle program may run without issuing a command before the run stops")
      ->capture_default_str();

  std::string check_world;
  CLI::App* check = app.add_subcommand("check", "Load and validate a world file, and build it in both modes");
  check->add_option("world", check_world, "World file (format turtlegas-world/1)")->required();
  check->add_option("--plugin", plugins, plugin_help);

  CLI::App* list = app.add_subcommand("controllers", "List the controllers world files can name, with their params");
  list->add_option("--plugin", plugins, plugin_help);

  turtlegas::apps::TestOptions test_opt;  // `turtlegas test` (test_command.hpp)
  CLI::App* test = turtlegas::apps::add_test_command(app, test_opt);
  test->add_option("--plugin", plugins, plugin_help);

  turtlegas::apps::TagCommandOptions tag_opt;  // `turtlegas tag` (tag_command.hpp)
  CLI::App* tag = turtlegas::apps::add_tag_command(app, tag_opt);
  tag->add_option("--plugin", plugins, plugin_help);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? exit_ok : exit_bad_input;
  }
  if (*dt_option) opt.dt = dt;

  try {
    tt::Registry registry = turtlegas::controllers::builtin_registry();
    load_plugins(plugins, registry);
    if (*list) return controllers_command(registry);
    if (*check) return check_command(check_world, registry);
    if (*test) return turtlegas::apps::test_command(test_opt, registry);
    if (*tag) {
      try {
        return turtlegas::apps::run_tag_command(tag_opt, registry);
      } catch (const turtlegas::apps::TagBadInput& e) {
        throw BadInput(e.what());
      }
    }
    return run_command(opt, registry);
  } catch (const BadInput& e) {
    spdlog::error("{}", e.what());
    return exit_bad_input;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return exit_failure;
  }
}
