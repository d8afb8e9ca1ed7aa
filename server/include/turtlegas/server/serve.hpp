// SPDX-License-Identifier: MIT
// `turtlegas serve`'s engine room: the listeners (HTTP + WebSocket, TCP lines), the io_context on
// a thread of its own, the world host on the calling thread (the simulation thread), SIGINT/SIGTERM.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "turtlegas/server/world_host.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/world/scene.hpp"

namespace turtlegas::server {

struct ServeOptions {
  std::string bind = "127.0.0.1";
  unsigned short port = 8080;           ///< 0: any free port
  std::optional<unsigned short> line_port;  ///< default: port + 1, or any free port when port is 0
  std::filesystem::path web_root;       ///< empty: default_web_root()
  /// Pages (origins, "http://name:port") that may use the WebSocket and names the HTTP side answers
  /// to, besides the server's own (docs/protocol.md, "Who gets in"); "*": any.
  std::vector<std::string> allow_origins;
  HostOptions host;
};

/// The default web root: the installed page beside the program (BINDIR/../share/turtlegas/web,
/// cmake --install and the .deb put it there) when it is there, else the source tree's server/web/.
std::filesystem::path default_web_root();

/// Serves the scene until a signal or --until; prints the two "listening" lines on stdout first.
/// Throws std::invalid_argument for a bad bind address, std::runtime_error when a port cannot be
/// had. Returns the exit code.
int serve(ServeOptions options, const turtle::Registry& registry, world::Scene scene);

}  // namespace turtlegas::server
