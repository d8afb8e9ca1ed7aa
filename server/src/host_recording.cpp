// SPDX-License-Identifier: MIT
// `turtlegas serve --record` (docs/recording.md, "Recording a served run"): the host writes the
// recording as `run --record` does, plus the inputs the world took from outside (the input log's
// lines, and the clients' views), so that `turtlegas replay` re-simulates the served run exactly.
// And a replay's own side: the inputs of a served run's recording fed back to its world, the
// views its clients opened kept across a seek that rebuilds the world.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "host_text.hpp"
#include "turtlegas/formats/input_log.hpp"
#include "turtlegas/formats/state_file.hpp"
#include "turtlegas/server/protocol.hpp"
#include "turtlegas/server/world_host.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/world/world_file.hpp"
#include "turtlegas/world/entries.hpp"

namespace turtlegas::server {

namespace {

double next_multiple(double t, double every) {
  return every > 0.0 ? (std::floor(t / every) + 1.0) * every : INFINITY;
}

}  // namespace

void WorldHost::start_recording() {
  if (options_.record_path.empty()) return;
  record_file_.emplace(options_.record_path, std::ios::binary | std::ios::trunc);
  if (!*record_file_) throw std::runtime_error("--record: cannot write '" + options_.record_path + "'");
  formats::RecordingHeader h;
  h.command = "serve";
  h.world_file = options_.world_file;
  try {
    h.world = nlohmann::ordered_json::parse(world_text());
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error("--record: the world file is not JSON (" + std::string(e.what()) + ")");
  }
  h.mode = sim::to_string(options_.mode);
  h.dt = scene_.def.dt;
  h.until = options_.until;
  h.keyframes = options_.keyframes;
  h.plugins = options_.plugins;
  recorder_.emplace(*record_file_, h);
  recorder_->keyframe(server_->world(), formats::RunNames{ball_ids_, scene_.def, server_->world()});
  next_key_ = next_multiple(server_->time(), options_.keyframes.seconds);
}

void WorldHost::advance(double target) {
  if (!recorder_) {
    if (options_.replay) replay_run_until(target);
    else server_->run_until(target);
    return;
  }
  // Cut at every multiple of the keyframe period, as `run --record` cuts its chunks there (a run
  // does not depend on where it is cut: docs/recording.md).
  auto keyframe = [&] {
    fan_out_events();  // the events up to the keyframe's time come before it
    recorder_->keyframe(server_->world(), formats::RunNames{ball_ids_, scene_.def, server_->world()});
  };
  while (next_key_ < target && recorder_) {
    server_->run_until(next_key_);
    keyframe();
    next_key_ = next_multiple(next_key_, options_.keyframes.seconds);
  }
  server_->run_until(target);
  if (!recorder_) return;
  const bool at_key = server_->time() >= next_key_;
  if (at_key) next_key_ = next_multiple(server_->time(), options_.keyframes.seconds);
  if (at_key || recorder_->keyframe_due(server_->world().stats().events)) keyframe();
}

void WorldHost::finish_recording(const std::string& stopped, bool keyframe) {
  if (!recorder_) return;
  fan_out_events();
  if (keyframe) recorder_->keyframe(server_->world(), formats::RunNames{ball_ids_, scene_.def, server_->world()});
  recorder_->finish(keyframe ? server_->time() : recorder_->last_keyframe_time(), stopped);
  recorder_.reset();
  record_file_->close();
  if (!*record_file_) output_failed("--record", options_.record_path);
  record_file_.reset();
  spdlog::info("recording '{}' closed at t={}{}", options_.record_path, server_->time(),
               stopped.empty() ? std::string() : " (" + stopped + ")");
}

void WorldHost::record_view(const char* op, const nlohmann::json& view) {
  if (recorder_) recorder_->input(input_line(formats::input_view_line(server_->step(), op, view)));
}

std::shared_ptr<turtle::InputSource> WorldHost::world_input() {
  if (!options_.replay || options_.replay->inputs.empty()) return nullptr;
  // A fresh reader for every build: a seek backwards replays the inputs from the start. A spawn
  // grows the host's scene as a live spawn does (host_world_changes.cpp), so that ids and frames name it.
  formats::SpawnApplier spawn = [this](turtle::WorldServer& server, const nlohmann::json& entry) {
    spawn_into_scene(server, entry, options_.replay->path);
  };
  std::istringstream in(options_.replay->inputs);
  return std::make_shared<formats::ReplayInput>(in, scene_.def, options_.replay->path, std::move(spawn));
}

void WorldHost::note_client_view(const char* op, const turtle::View& view) {
  if (!options_.replay) return;
  const auto it = std::find_if(client_views_.begin(), client_views_.end(), [&](const turtle::View& v) { return v.id == view.id; });
  const std::string o = op;
  if (o == "open") client_views_.push_back(view);
  else if (it != client_views_.end() && o == "change") *it = view;
  else if (it != client_views_.end()) client_views_.erase(it);
}

void WorldHost::reopen_client_views() {
  for (const turtle::View& v : client_views_) {
    try {
      if (server_->find_view(v.id)) server_->change_view(v);
      else server_->open_view(v);
    } catch (const std::invalid_argument& e) {
      // A view following a turtle that is not there at this time (spawned later): shown again
      // after a seek to a time it exists at.
      spdlog::info("replay: view '{}' is not shown at t={}: {}", v.id, server_->time(), e.what());
    }
  }
}

void WorldHost::plan_snapshots() {
  max_snapshots_ = 0;
  if (!options_.replay || !options_.replay->inputs.empty() || !server_->snapshot()) return;
  // About 400 bytes a ball in the engine and the scene; at most 512 MiB of snapshots.
  const double bytes = 400.0 * static_cast<double>(server_->world().ball_count() + 16);
  max_snapshots_ = static_cast<std::size_t>(std::clamp(512.0 * 1024 * 1024 / bytes, 1.0, 4096.0));
}

void WorldHost::replay_run_until(double t) {
  const std::vector<formats::Keyframe>& keys = options_.replay->keyframes;
  check_reached_keyframes();
  auto later = [](double time, const formats::Keyframe& k) { return time < k.t; };
  for (auto k = std::upper_bound(keys.begin(), keys.end(), server_->time(), later); k != keys.end() && k->t <= t; ++k) {
    const bool compare = !replay_diverged_ && static_cast<std::size_t>(k - keys.begin()) >= keys_checked_;
    const bool snapshot = snapshots_.size() < max_snapshots_ && !snapshots_.contains(k->t);
    if (!compare && !snapshot) continue;
    // Cut at the keyframe (a run does not depend on where it is cut), compare, copy the world there.
    server_->run_until(k->t);
    check_reached_keyframes();
    if (snapshot) snapshots_.emplace(k->t, server_->snapshot());
  }
  server_->run_until(t);
  check_reached_keyframes();
}

void WorldHost::check_reached_keyframes() {
  const std::vector<formats::Keyframe>& keys = options_.replay->keyframes;
  while (keys_checked_ < keys.size() && keys[keys_checked_].t <= server_->time()) {
    const formats::Keyframe& k = keys[keys_checked_++];
    if (replay_diverged_ || k.t != server_->time()) continue;
    const std::optional<std::string> d =
        formats::keyframe_difference(formats::read_keyframe(options_.replay->path, k), server_->world(),
                                     formats::RunNames{ball_ids_, scene_.def, server_->world()});
    if (!d) continue;
    replay_diverged_ = true;
    spdlog::warn("{}: at t = {} s this replay differs from the recording's keyframe ({}): the recorded world, a "
                 "program, or this build differs from the one that recorded it, and the viewer shows this run, "
                 "not the recorded one",
                 options_.replay->path, fmt(k.t), *d);
  }
}

bool WorldHost::restore_snapshot(double t) {
  auto it = snapshots_.upper_bound(t);
  if (it == snapshots_.begin()) return false;
  --it;
  if (!(t < server_->time()) && !(it->first > server_->time())) return false;
  server_->restore(*it->second);
  return true;
}

std::string WorldHost::state_text() const {
  std::ostringstream out;
  formats::write_state(out, server_->world(), formats::RunNames{ball_ids_, scene_.def, server_->world()});
  return out.str();
}

void WorldHost::require_not_replay(const std::string& type) const {
  if (options_.replay)
    throw RequestError("replay", "\"" + type + "\" would change the world, and this is a replay of " + options_.replay->path +
                                     ": it can only play, pause, seek, reverse, step and change speed");
}

bool WorldHost::replay_target(double& target) {
  const double t = server_->time(), dt = scene_.def.dt, end = options_.replay->end;
  if (!reverse_ || steps_left_ > 0) {
    if (t >= end) return false;
    if (!(target > t)) target = std::nextafter(t, INFINITY);
    target = std::min(target, end);
    return true;
  }
  if (t <= 0.0) return false;
  target = dt > 0.0 ? std::max(0.0, (std::ceil(t / dt) - 1.0) * dt) : 0.0;
  if (!(target < t)) target = std::max(0.0, target - dt);
  return true;
}

void WorldHost::seek(double t) {
  const bool back = t < server_->time();
  fan_out_events();
  const bool restored = restore_snapshot(t);
  const bool rebuild = back && !restored;
  if (rebuild) {
    world::Scene scene = world::parse_scene(world_text(), options_.world_file, registry_);
    scene.def.dt = options_.replay->dt;
    build_world(std::move(scene));
  }
  in_step_ = true;
  try {
    seek_run_until(t);
  } catch (const std::exception& e) {
    in_step_ = false;
    events_.clear();
    end_world(e.what());
    return;
  }
  in_step_ = false;
  if (rebuild || restored) reopen_client_views();
  events_.clear();  // what happened on the way is not shown: the viewer jumps
  reanchor();
  if (!rebuild && !restored) return;
  std::map<std::string, FrameStream> fresh;
  for (auto& [key, s] : streams_) fresh.try_emplace(key, s.kind(), *server_).first->second.next_due = now();
  streams_ = std::move(fresh);
  for (auto& [cid, c] : clients_)
    if (c.stream) reply_text(c, snapshot_text(*server_, ball_ids_, claimed(), clock(), nullptr, world_json()["arena"], looks_));
}


void WorldHost::check_replay() {
  if (!options_.replay) return;
  ReplaySource& r = *options_.replay;
  if (!(std::isfinite(r.dt) && r.dt >= 0.0 && r.dt <= 1e6))
    throw std::invalid_argument(r.path + ": the header's dt (" + fmt(r.dt) +
                                " s) is not a time step from 0 to 1e6 s; the recording is damaged");
  double before = 0.0;
  for (const formats::Keyframe& k : r.keyframes)
    if (!(std::isfinite(k.t) && k.t >= before)) throw std::invalid_argument(r.path + ": keyframe times out of order or not finite; the recording is damaged");
    else before = k.t;
  if (!(r.end >= 0.0) || !std::isfinite(r.end) || (!r.keyframes.empty() && r.end > r.keyframes.back().t)) {
    // A recording ends on its last keyframe (formats/recording.cpp writes one at its end): an index
    // claiming more would make a seek run for ever.
    const double last = r.keyframes.empty() ? 0.0 : r.keyframes.back().t;
    spdlog::warn("{}: its index says it ends at t={} s, but its last keyframe is at t={} s; it is replayed to {} s",
                 r.path, fmt(r.end), fmt(last), fmt(last));
    r.end = last;
  }
  if (r.dt > 0.0 && r.end / r.dt > 1e12)
    throw std::invalid_argument(r.path + ": " + fmt(r.end) + " s at dt " + fmt(r.dt) +
                                " s are more than 1e12 control steps; the recording is damaged");
}

bool WorldHost::stop_requested() {
  std::lock_guard lock(mutex_);
  for (const Inbound& in : inbox_)
    if (in.kind == Inbound::Kind::stop) {
      stopping_ = true;
      stop_reason_ = in.reason;
      return true;
    }
  return false;
}

void WorldHost::seek_run_until(double t) {
  // The other messages wait for the seek's end (handled mid-way, a seek or a state request would
  // see the world on its way); only a stop cuts it short, so a long seek never holds SIGTERM up.
  constexpr double kChunk = 0.05;  // wall seconds
  const double dt = scene_.def.dt;
  double span = dt > 0.0 ? 16.0 * dt : t;
  while (server_->time() < t && !stop_requested()) {
    const double from = server_->time(), start = now();
    double next = std::min(t, from + span);
    if (!(next > from)) next = t;
    replay_run_until(next);
    if (!(server_->time() > from)) break;  // it cannot go on (the world ended)
    const double took = now() - start;
    if (took < kChunk / 2) span *= 2.0;
    else if (took > 2 * kChunk && dt > 0.0) span = std::max(dt, span / 2.0);
  }
}

}  // namespace turtlegas::server
