// SPDX-License-Identifier: MIT
// What the libFuzzer harnesses share: the registry (built-in controllers), and a bounded run of a
// scene, so that a harness reaches the engine and the runtime, not only the loader, and a slow
// scene costs a bounded number of events rather than a timeout.
#pragma once

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string_view>

#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/turtle/world_server.hpp"
#include "turtlegas/world/file_error.hpp"
#include "turtlegas/world/scene.hpp"
#include "turtlegas/world/world_file.hpp"

namespace turtlegas::fuzz {

inline const turtle::Registry& registry() {
  static const turtle::Registry r = controllers::builtin_registry();
  return r;
}

/// A finding that is no crash of its own (an exception where an answer was due): says what and
/// aborts, which libFuzzer saves as a crash.
[[noreturn]] inline void finding(const char* what, const char* message) {
  std::fprintf(stderr, "finding: %s: %s\n", what, message);
  std::abort();
}

/// The scene of a fuzzed world file's bytes, or nullopt when the loader refuses it with its
/// WorldFileError (the expected answer to most inputs).
inline std::optional<world::Scene> load_scene(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    return world::parse_scene(text, "fuzz.json", registry());
  } catch (const world::WorldFileError&) {
    return std::nullopt;
  }
}

/// A private directory /tmp/NAME-PID-XXXXXX for a harness's files. libFuzzer ends its fork-mode
/// jobs without running atexit handlers, so the sandboxes of processes that are gone are removed
/// here, when the next one is made.
inline std::filesystem::path make_sandbox(const std::string& name) {
  namespace fs = std::filesystem;
  const std::string prefix = name + "-";
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator("/tmp", ec)) {
    const std::string leaf = e.path().filename().string();
    if (leaf.rfind(prefix, 0) != 0) continue;
    const long pid = std::strtol(leaf.c_str() + prefix.size(), nullptr, 10);
    if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) fs::remove_all(e.path(), ec);
  }
  std::string tmpl = "/tmp/" + prefix + std::to_string(::getpid()) + "-XXXXXX";
  if (::mkdtemp(tmpl.data()) == nullptr) finding("sandbox", "cannot make a directory in /tmp");
  return tmpl;
}

/// Bounds of a fuzzed run: at most this many engine events, this much simulated time, and this
/// many control steps (a tiny dt would otherwise cost its steps however few events they hold).
inline constexpr std::uint64_t max_events = 20000;
inline constexpr double max_time = 5.0;
inline constexpr double max_steps = 500;
/// Scenes with more bodies are loaded but not run: a run's cost grows with them (step mode moves
/// every ball every step), and a large scene reaches nothing a small one does not.
inline constexpr std::size_t max_bodies = 1000;

/// Runs the scene in `mode` in chunks until one of the bounds; the invariants a run must keep
/// (no NaN in positions) abort, which libFuzzer reports as a crash.
inline void bounded_run(const world::Scene& scene, sim::Mode mode) {
  if (scene.def.balls.size() + scene.def.turtles.size() > max_bodies) return;
  const double steps = max_time / scene.def.dt;
  const double until = steps > max_steps ? max_steps * scene.def.dt : max_time;
  const double chunk = until / 64.0;
  if (!(chunk > 0.0)) return;
  auto check = [](const sim::World& w) {
    for (std::size_t i = 0; i < w.ball_count(); ++i) {
      const sim::BallState b = w.ball(i);
      if (b.alive && !(std::isfinite(b.pos.x) && std::isfinite(b.pos.y))) __builtin_trap();
    }
  };
  // The event bound holds inside a chunk too (the engine's event limit): a ball at 1e66 units/s, or
  // an ion gyrating 1e36 times a second, makes more than any bound's worth of events in one
  // chunk, and the harness once waited for them (timeouts that were the harness's, not hangs: the
  // CLI's --max-events stops the same scenes in milliseconds).
  if (scene.def.turtles.empty()) {
    sim::WorldDef def = scene.def;
    sim::World world(std::move(def), mode);
    world.set_event_limit(max_events);
    try {
      for (double t = chunk; t <= until; t += chunk) world.advance_to(t);
    } catch (const sim::EventLimitReached&) {
      // the bound: the world is consistent as of its last event
    }
    check(world);
    return;
  }
  turtle::ServerOptions options;
  options.mode = mode;
  options.program_budget = 1.0;
  const std::unique_ptr<turtle::WorldServer> server = world::make_server(scene, registry(), options);
  server->set_event_limit(max_events);
  try {
    for (double t = chunk; t <= until; t += chunk) server->run_until(t);
  } catch (const turtle::BusyLoopError&) {
    return;  // a controller's own busy loop: the documented end of a run
  } catch (const sim::EventLimitReached&) {
    // the bound
  }
  check(server->world());
}

}  // namespace turtlegas::fuzz
