// SPDX-License-Identifier: MIT
#include "serve_command.hpp"

#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include <spdlog/spdlog.h>

#include "cli_common.hpp"
#include "plugins.hpp"
#include "output_file.hpp"
#include "turtlegas/formats/recording.hpp"
#include "turtlegas/world/file_error.hpp"
#include "turtlegas/world/world_file.hpp"
#include "turtlegas/server/serve.hpp"
#include "turtlegas/sim/mode_names.hpp"

namespace turtlegas::apps {
namespace {

// Range checks on the option's text, as for every command (cli_common.hpp): CLI11 alone read
// `--max-clients -1` as 2^64 - 1 and took `--lockstep-timeout 1e308` (a wait whose conversion to
// the clock's nanoseconds overflows) and `--max-rate inf`.
constexpr std::int64_t max_count = 1000000;
constexpr std::int64_t max_message_bytes = std::int64_t{1} << 30;

void add_port_options(CLI::App& s, ServeCommandOptions& opt) {
  s.add_option("--port", opt.port, "HTTP and WebSocket port (0: any free port)")
      ->capture_default_str()
      ->check(integer_in(0, 65535, "port"));
  s.add_option("--line-port", opt.line_port, "TCP-lines port (default: --port + 1; any free port when --port is 0)")
      ->check(integer_in(0, 65535, "port"));
}

void add_max_clients_option(CLI::App& s, ServeCommandOptions& opt) {
  s.add_option("--max-clients", opt.max_clients, "Connections at most (WebSocket and TCP lines)")
      ->capture_default_str()
      ->check(integer_in(1, max_count, "connections"));
}

}  // namespace

namespace {

void add_door_options(CLI::App& s, ServeCommandOptions& opt) {
  s.add_option("--token-file", opt.token_file, "Read the token from this file (its first line); the environment's TURTLEGAS_TOKEN is the other way");
  s.add_option("--allow-origin", opt.allow_origins,
               "Let the page at this origin (http://name:port) use the WebSocket, and answer HTTP for that name; "
               "'*' for any (by default only 127.0.0.1, localhost, [::1] and --bind, with the port)")
      ->check(
          [](const std::string& o) -> std::string {
            // An origin is what a browser sends: scheme://host[:port], nothing after. Before, "" and
            // "localhost:8080" were taken silently and allowed no page at all.
            if (o == "*") return {};
            const std::size_t scheme = o.find("://");
            const bool ok = scheme != std::string::npos && scheme > 0 && o.size() > scheme + 3 &&
                            o.find_first_of("/?# ", scheme + 3) == std::string::npos;
            if (ok) return {};
            return "'" + o + "' is not an origin: give it as a browser sends it, scheme://name[:port] "
                   "(e.g. http://robots.lab:8080), or '*' for any";
          },
          "ORIGIN");
}

/// --token, else --token-file's first line, else $TURTLEGAS_TOKEN, else none.
std::optional<std::string> read_token(const ServeCommandOptions& opt) {
  if (!opt.token.empty() && !opt.token_file.empty()) throw BadInput("--token and --token-file: give one of them");
  if (!opt.token.empty()) return opt.token;
  if (!opt.token_file.empty()) {
    std::ifstream in(opt.token_file, std::ios::binary);
    std::string line;
    if (!in || !std::getline(in, line)) throw BadInput("--token-file: cannot read '" + opt.token_file + "'");
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
    if (line.empty()) throw BadInput("--token-file: '" + opt.token_file + "' has an empty first line; put the token there");
    return line;
  }
  if (const char* env = std::getenv("TURTLEGAS_TOKEN"); env && *env) return std::string(env);
  return std::nullopt;
}

}  // namespace

CLI::App* add_serve_command(CLI::App& app, ServeCommandOptions& opt) {
  CLI::App* s = app.add_subcommand("serve", "Run a world in real time and serve it on the network (docs/protocol.md)");
  s->add_option("world", opt.world, "World file (format turtlegas-world/1)")->required();
  s->add_option("--bind", opt.bind, "Address to listen on; other than loopback needs --token")->capture_default_str();
  add_port_options(*s, opt);
  s->add_option("--speed", opt.speed, "Simulated seconds per wall second, 0.01 to 1000, or max")->capture_default_str();
  s->add_flag("--paused", opt.paused, "Start paused");
  s->add_option("--token", opt.token, "Token that control messages and claims need (shows in `ps`: prefer --token-file or TURTLEGAS_TOKEN)");
  add_door_options(*s, opt);
  s->add_option("--until", opt.until, "Stop at this simulated time, as on SIGINT")
      ->check(real_in(0, std::numeric_limits<double>::max(), "seconds"));
  s->add_option("--events", opt.events, "Write the event log here (JSON lines, as `run --events`)");
  s->add_option("--inputs-out", opt.inputs_out, "Write the input log here (replay with `run --inputs`)");
  s->add_option("--record", opt.record,
                "Write a recording of the served run here, inputs and views included (docs/recording.md; play it "
                "with `turtlegas replay`)");
  s->add_option("--keyframe-seconds", opt.keyframe_seconds, "A recording's keyframe every this many simulated seconds (0: none)")
      ->capture_default_str()
      ->check(real_in(0, 1e9, "seconds"));
  s->add_option("--keyframe-events", opt.keyframe_events, "A recording's keyframe after this many engine events (0: none)")
      ->capture_default_str()
      ->check(integer_in(0, std::numeric_limits<std::int64_t>::max(), "events"));
  s->add_option("--save-dir", opt.save_dir, "The only directory save and load may touch");
  s->add_option("--web-root", opt.web_root, "Static files for GET / (default: the installed share/turtlegas/web beside the program, else the source tree's server/web)");
  add_max_clients_option(*s, opt);
  s->add_option("--max-claims", opt.max_claims, "Claimed turtles per connection at most")
      ->capture_default_str()
      ->check(integer_in(0, max_count, "claims"));
  s->add_option("--max-message", opt.max_message, "Bytes per message at most")
      ->capture_default_str()
      ->check(integer_in(64, max_message_bytes, "bytes"));
  s->add_option("--max-rate", opt.max_rate, "Messages per second per connection at most")
      ->capture_default_str()
      ->check(real_in(0, 1e9, "messages per second", true));
  s->add_option("--lockstep-timeout", opt.lockstep_timeout,
                "Wall seconds a lockstep world waits for a claimed turtle's command before it ends")
      ->capture_default_str()
      ->check(real_in(0, 1e6, "seconds", true));
  s->add_option("--mode", opt.mode, "exact (event-driven) or step (the memo's fixed steps)")
      ->check(CLI::IsMember(sim::mode_names))
      ->capture_default_str();
  s->add_flag("--realtime", opt.realtime, "Remote turtles never hold the world up (default: lockstep)");
  add_stack_kib_option(*s, opt.stack_kib);
  add_program_budget_option(*s, opt.program_budget, "its world ends");
  return s;
}

CLI::App* add_replay_command(CLI::App& app, ServeCommandOptions& opt) {
  CLI::App* s = app.add_subcommand(
      "replay", "Serve a recording (run --record) to the viewer and the protocol: play, pause, seek, reverse, speed");
  s->add_option("recording", opt.replay, "The recording (format turtlegas-recording/1, docs/recording.md)")->required();
  s->add_option("--bind", opt.bind, "Address to listen on; other than loopback needs --token")->capture_default_str();
  add_port_options(*s, opt);
  s->add_option("--speed", opt.speed, "Simulated seconds per wall second, 0.01 to 1000, or max")->capture_default_str();
  s->add_flag("--paused", opt.paused, "Start paused");
  s->add_option("--token", opt.token, "Token that control messages need (shows in `ps`: prefer --token-file or TURTLEGAS_TOKEN)");
  add_door_options(*s, opt);
  s->add_option("--web-root", opt.web_root, "Static files for GET / (default: the installed share/turtlegas/web beside the program, else the source tree's server/web)");
  add_max_clients_option(*s, opt);
  add_stack_kib_option(*s, opt.stack_kib);
  return s;
}

PreparedServe prepare_serve(const ServeCommandOptions& opt, const turtle::Registry& registry) {
  PreparedServe prepared;
  server::ServeOptions& so = prepared.options;
  so.bind = opt.bind;
  if (opt.port > 65535) throw BadInput("--port must be from 0 to 65535 (got " + std::to_string(opt.port) + ")");
  so.port = static_cast<unsigned short>(opt.port);
  if (opt.line_port) {
    if (*opt.line_port > 65535) throw BadInput("--line-port must be from 0 to 65535");
    so.line_port = static_cast<unsigned short>(*opt.line_port);
  }
  so.web_root = opt.web_root;

  server::HostOptions& h = so.host;
  if (opt.speed == "max") {
    h.speed = 0.0;
  } else {
    try {
      std::size_t used = 0;
      h.speed = std::stod(opt.speed, &used);
      if (used != opt.speed.size()) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      throw BadInput("--speed must be a number from 0.01 to 1000, or max (got '" + opt.speed + "')");
    }
    if (!(h.speed >= 0.01 && h.speed <= 1000.0))
      throw BadInput("--speed must be from 0.01 to 1000, or max (got " + opt.speed + ")");
  }
  if (opt.until && (!std::isfinite(*opt.until) || *opt.until < 0.0))
    throw BadInput("--until must be a finite time >= 0 in seconds");
  if (!(opt.lockstep_timeout > 0.0 && std::isfinite(opt.lockstep_timeout)))
    throw BadInput("--lockstep-timeout must be a finite number of seconds > 0");
  if (!(opt.max_rate > 0.0)) throw BadInput("--max-rate must be > 0");
  if (opt.max_message < 64) throw BadInput("--max-message must be at least 64 bytes");
  if (opt.max_clients < 1) throw BadInput("--max-clients must be at least 1");
  if (opt.stack_kib < 16 || opt.stack_kib > 1024 * 1024) throw BadInput("--stack-kib must be from 16 to 1048576");
  if (!(opt.program_budget > 0.0 && std::isfinite(opt.program_budget))) throw BadInput("--program-budget must be > 0");
  h.world_file = opt.world;
  h.mode = sim::mode_from_string(opt.mode).value_or(sim::Mode::exact);
  h.realtime = opt.realtime;
  h.paused = opt.paused;
  h.until = opt.until;
  h.events_path = opt.events;
  h.inputs_path = opt.inputs_out;
  // As `run` checks its outputs: none may be the world file (by any name) or another output, and a
  // directory is no file to write (serve --events worlds/tag.json overwrote the world before).
  check_outputs({{opt.events, "--events"}, {opt.inputs_out, "--inputs-out"}, {opt.record, "--record"}},
                {{opt.world, "the world file"}});
  for (const auto& [path, option] : {std::pair{&opt.events, "--events"}, {&opt.inputs_out, "--inputs-out"}, {&opt.record, "--record"}}) {
    std::error_code de;
    if (!path->empty() && *path != "-" && std::filesystem::is_directory(*path, de))
      throw BadInput(std::string(option) + " " + *path + ": that is a directory; give a file name");
  }
  if (!opt.record.empty()) {
    if (opt.record == "-") throw BadInput("--record needs a file name, not standard output (replay seeks in it)");
    h.record_path = opt.record;
    h.keyframes = {opt.keyframe_seconds, opt.keyframe_events};
  }
  if (!opt.save_dir.empty()) {
    std::error_code fe;
    if (!std::filesystem::is_directory(opt.save_dir, fe))
      throw BadInput("--save-dir: '" + opt.save_dir + "' is not a directory; create it first");
    h.save_dir = std::filesystem::canonical(opt.save_dir, fe);
  }
  h.token = read_token(opt);
  so.allow_origins = opt.allow_origins;
  h.lockstep_timeout = opt.lockstep_timeout;
  h.stack_bytes = opt.stack_kib * 1024;
  h.program_budget = opt.program_budget;
  h.limits.max_clients = opt.max_clients;
  h.limits.max_claims = opt.max_claims;
  h.limits.max_message = opt.max_message;
  h.limits.max_rate = opt.max_rate;
  if (h.limits.max_websocket_read < opt.max_message) h.limits.max_websocket_read = opt.max_message;

  world::Scene& scene = prepared.scene;
  if (!opt.replay.empty()) {
    // The recording's world, re-simulated: the run is deterministic, so its states are the
    // recorded ones to the bit (docs/recording.md, "Replay").
    formats::Recording rec;
    try {
      rec = formats::read_recording(opt.replay);
    } catch (const std::invalid_argument& e) {
      throw BadInput(e.what());
    }
    if (!rec.warning.empty()) spdlog::warn("{}; the replay ends there", rec.warning);
    const std::string label = rec.header.world_file + " (recorded in " + opt.replay + ")";
    h.world_text = rec.header.world.dump(2);
    try {
      scene = world::parse_scene(h.world_text, label, registry);
    } catch (const world::WorldFileError& e) {
      throw BadInput(opt.replay + ": the recorded world does not load here: " + std::string(e.what()));
    }
    scene.def.dt = rec.header.dt;
    const auto mode = sim::mode_from_string(rec.header.mode);
    if (!mode) throw BadInput(opt.replay + ": /mode '" + rec.header.mode + "' is not exact or step; the recording is damaged");
    h.mode = *mode;
    h.world_file = label;
    server::ReplaySource r;
    r.path = opt.replay;
    r.end = rec.end;
    r.dt = rec.header.dt;
    r.complete = rec.complete;
    r.keyframes = rec.keyframes;
    if (rec.header.command == "serve")  // its inputs, up to where the recording is whole
      r.inputs = formats::recording_inputs(opt.replay, rec.complete ? rec.bytes : rec.keyframes.back().offset,
                                           scene.def.name, rec.header.dt);
    h.replay = std::move(r);
    h.until.reset();
  } else {
    scene = load(opt.world, registry);
    std::vector<std::string> controllers;
    for (const turtle::TurtleProgram& p : scene.programs) controllers.push_back(p.controller);
    h.plugins = plugins_used(controllers);
    std::ifstream in(opt.world, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    h.world_text = text.str();
  }
  return prepared;
}

int serve_command(const ServeCommandOptions& opt, const turtle::Registry& registry) {
  PreparedServe prepared = prepare_serve(opt, registry);
  try {
    return server::serve(std::move(prepared.options), registry, std::move(prepared.scene));
  } catch (const std::invalid_argument& e) {
    throw BadInput(e.what());
  }
}

}  // namespace turtlegas::apps
