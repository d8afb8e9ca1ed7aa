// SPDX-License-Identifier: MIT
// The world host's world: opening the logs, building the one WorldServer from a scene (at start
// and on `load`), and the world file's text for GET /api/world.
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "turtlegas/formats/input_log.hpp"
#include "turtlegas/server/world_host.hpp"
#include "turtlegas/world/world_file.hpp"

namespace turtlegas::server {

WorldHost::WorldHost(HostOptions options, const turtle::Registry& registry, world::Scene scene)
    : options_(std::move(options)), registry_(registry) {
  check_replay();
  paused_ = options_.paused;
  speed_ = options_.speed;
  input_ = remote_input();
  if (!options_.events_path.empty()) {
    events_file_.emplace(options_.events_path, std::ios::binary | std::ios::trunc);
    if (!*events_file_) throw std::runtime_error("--events: cannot write '" + options_.events_path + "'");
    events_writer_.emplace(*events_file_);
  }
  if (!options_.inputs_path.empty()) {
    inputs_file_.emplace(options_.inputs_path, std::ios::binary | std::ios::trunc);
    if (!*inputs_file_) throw std::runtime_error("--inputs-out: cannot write '" + options_.inputs_path + "'");
    // The header on disk at once, and each input as it is taken (write_input): a server killed
    // with SIGKILL leaves an input log that `run --inputs` replays up to its last line.
    *inputs_file_ << formats::input_header_line(scene.def.name, scene.def.dt);
    inputs_file_->flush();
    if (!*inputs_file_)
      throw std::runtime_error("--inputs-out: writing '" + options_.inputs_path + "' failed (" + std::strerror(errno) + ")");
  }
  served_file_ = options_.world_file;
  build_world(std::move(scene));
  start_recording();
  plan_snapshots();
}

WorldHost::~WorldHost() = default;

void WorldHost::build_world(world::Scene scene) {
  scene_ = std::move(scene);
  ball_ids_ = formats::ball_ids(scene_.def);
  turtle::ServerOptions o;
  o.mode = options_.mode;
  o.stack_bytes = options_.stack_bytes;
  o.program_budget = options_.program_budget;
  o.input = world_input();
  if (!o.input) o.input = input_;
  o.remote_reports = [this](const turtle::RemoteReport& r) { on_report(r); };
  server_.reset();
  server_ = world::make_server(scene_, registry_, o);
  server_->set_event_log(&events_);
  slots_.assign(server_->turtle_count(), Slot{});
  looks_.clear();
  const sim::WorldDef layered = turtle::with_builder_layers(scene_.def, scene_.programs);
  for (std::size_t i = 0; i < layered.turtles.size(); ++i) looks_.push_back({layered.turtles[i].layers, scene_.programs[i].sensors});
  wall_changes_.clear();
  body_changes_.clear();
  takeovers_.clear();
  ended_.reset();
  pause_at_.reset();
  steps_left_ = 0;
  reanchor();
}

std::string WorldHost::world_text() const {
  std::lock_guard lock(text_mutex_);
  return options_.world_text;
}

}  // namespace turtlegas::server
