// SPDX-License-Identifier: MIT
// `turtlegas serve WORLD.json ...`: the world on the network (docs/protocol.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "turtlegas/server/serve.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/world/scene.hpp"

namespace turtlegas::apps {

struct ServeCommandOptions {
  std::string world;
  std::string bind = "127.0.0.1";
  unsigned port = 8080;
  std::optional<unsigned> line_port;
  std::string speed = "1";
  bool paused = false;
  std::string token;
  std::string token_file;  ///< --token-file: the token read from here (kept out of `ps`)
  std::vector<std::string> allow_origins;  ///< --allow-origin (docs/protocol.md, "Who gets in")
  std::optional<double> until;
  std::string events, inputs_out, save_dir, web_root;
  std::size_t max_clients = 64, max_claims = 8, max_message = 1024 * 1024;
  double max_rate = 20000;
  double lockstep_timeout = 10.0;
  std::string mode = "exact";
  bool realtime = false;
  std::size_t stack_kib = 32;
  double program_budget = 2.0;
  std::string record;  ///< `serve --record R.tgrec` (docs/recording.md)
  double keyframe_seconds = 1.0;
  std::uint64_t keyframe_events = 100000;
  std::string replay;  ///< `turtlegas replay R.tgrec`: the recording served (docs/recording.md)
};

CLI::App* add_serve_command(CLI::App& app, ServeCommandOptions& opt);
/// `turtlegas replay R.tgrec [--port P] [--bind A] ...`: a recording served as `serve` serves a
/// world, to the same viewers and protocol, with play, pause, seek, reverse and speed. Its options
/// are serve's that make sense for a recording; serve_command() runs it.
CLI::App* add_replay_command(CLI::App& app, ServeCommandOptions& opt);
/// What serve_command() checks and loads before it listens: the options range-checked, the world
/// (or the recording's world) loaded; BadInput for anything wrong. Nothing is opened or bound.
struct PreparedServe {
  server::ServeOptions options;
  world::Scene scene;
};
PreparedServe prepare_serve(const ServeCommandOptions& opt, const turtle::Registry& registry);
/// prepare_serve(), then serves until a signal or --until.
int serve_command(const ServeCommandOptions& opt, const turtle::Registry& registry);

}  // namespace turtlegas::apps
