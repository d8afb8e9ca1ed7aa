// SPDX-License-Identifier: MIT
// `turtlegas serve WORLD.json ...`: the world on the network (docs/protocol.md).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

struct ServeCommandOptions {
  std::string world;
  std::string bind = "127.0.0.1";
  unsigned port = 8080;
  std::optional<unsigned> line_port;
  std::string speed = "1";
  bool paused = false;
  std::string token;
  std::optional<double> until;
  std::string events, inputs_out, save_dir, web_root;
  std::size_t max_clients = 64, max_claims = 8, max_message = 1024 * 1024;
  double max_rate = 20000;
  double lockstep_timeout = 10.0;
  std::string mode = "exact";
  bool realtime = false;
  std::size_t stack_kib = 32;
  double program_budget = 2.0;
};

CLI::App* add_serve_command(CLI::App& app, ServeCommandOptions& opt);
int serve_command(const ServeCommandOptions& opt, const turtle::Registry& registry);

}  // namespace turtlegas::apps
