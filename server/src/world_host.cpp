// SPDX-License-Identifier: MIT
// The world host's loop (the simulation thread): the inbox across threads, pacing, and the order
// of one turn of the loop. The rest of WorldHost lives in host_*.cpp, one role a file:
//   host_world.cpp          building the world, its text
//   host_messages.cpp       the message table: each protocol message's name, who may send it, its handler
//   host_replies.cpp        replies, status and world JSON, request helpers
//   host_frames.cpp         fan-out of events and frames, subscribe and snapshot, end_world
//   host_control.cpp        pause, resume, step, speed, run_until; a replay's play, seek, reverse
//   host_remote.cpp         remote turtles: claim, release, commands, lockstep
//   host_world_changes.cpp  add_wall, spawn, remove, teleport
//   host_views.cpp          view_open, view_change, view_close
//   host_files.cpp          save and load, the input log
//   host_recording.cpp      serve --record, and a replay's side (seek, snapshots)
//
// One turn of run()'s loop, in this order:
//   1. drain the inbox: every message that came in is handled (replies at once; changes queued);
//   2. save and load requests (host_files.cpp), which may replace the world;
//   3. frames due are sent (host_frames.cpp);
//   4. paused or ended: wait for the inbox or the next frame, and start again;
//   5. pacing: wait until the wall clock reaches the next control step's time (at --speed);
//   6. the world advances one control step (step_world). At each control boundary inside it
//      (at_boundary, called by the runtime): the inbox is drained again, then claims with takeover,
//      walls, and spawn/remove/teleport are applied, in that order, and written to the input log;
//      a lockstep remote turtle's command is waited for there (next_command, host_remote.cpp),
//      and changes and saves that come meanwhile are made there and then (their senders may wait
//      for them before they send that command);
//   7. the step's events go to the event log, the recording and the subscribers' frames;
//   8. a `step` count or a run_until's time reached pauses; --until stops.
#include "turtlegas/server/world_host.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include <spdlog/spdlog.h>

#include "host_text.hpp"

namespace turtlegas::server {

using nlohmann::json;

// ---- from any thread --------------------------------------------------------------------------

void WorldHost::connected(std::shared_ptr<Client> client) {
  ++clients_open_;
  std::lock_guard lock(mutex_);
  inbox_.push_back({Inbound::Kind::connect, std::move(client), {}, {}, {}});
  inbox_ready_.store(true, std::memory_order_release);
  cv_.notify_one();
}

void WorldHost::disconnected(std::shared_ptr<Client> client) {
  --clients_open_;
  std::lock_guard lock(mutex_);
  inbox_.push_back({Inbound::Kind::disconnect, std::move(client), {}, {}, {}});
  inbox_ready_.store(true, std::memory_order_release);
  cv_.notify_one();
}

void WorldHost::post(std::shared_ptr<Client> client, json message) {
  std::lock_guard lock(mutex_);
  inbox_.push_back({Inbound::Kind::message, std::move(client), std::move(message), {}, {}});
  inbox_ready_.store(true, std::memory_order_release);
  cv_.notify_one();
}

void WorldHost::request_state(std::function<void(std::string)> done) {
  std::lock_guard lock(mutex_);
  inbox_.push_back({Inbound::Kind::state, nullptr, {}, std::move(done), {}});
  inbox_ready_.store(true, std::memory_order_release);
  cv_.notify_one();
}

void WorldHost::request_stop(std::string reason) {
  std::lock_guard lock(mutex_);
  inbox_.push_back({Inbound::Kind::stop, nullptr, {}, {}, std::move(reason)});
  inbox_ready_.store(true, std::memory_order_release);
  cv_.notify_one();
}

// ---- the simulation thread ----------------------------------------------------------------------

double WorldHost::now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void WorldHost::reanchor() {
  anchor_wall_ = now();
  anchor_sim_ = server_ ? server_->time() : 0.0;
}

void WorldHost::drain_inbox() {
  std::deque<Inbound> batch;
  {
    std::lock_guard lock(mutex_);
    if (inbox_.empty()) return;  // most boundaries: no deque to build (it allocates) and free
    batch.swap(inbox_);
    inbox_ready_.store(false, std::memory_order_relaxed);
  }
  for (Inbound& in : batch) handle(in);
}

bool WorldHost::wait_inbox_until(double deadline) {
  // Spin a little before sleeping: a lockstep client's next command usually arrives within tens of
  // microseconds, and waking a sleeping thread on an idle vCPU costs as much again (measured: a
  // command that waits for a control step took ~80 us more on the quiet machine than under load;
  // docs/performance.md). At most kSpin of CPU per wait, so pacing and paused waits lose nothing.
  constexpr double kSpin = 100e-6;
  const double spin_end = std::min(deadline, now() + kSpin);
  while (now() < spin_end) {
    if (inbox_ready_.load(std::memory_order_acquire)) return true;
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
  std::unique_lock lock(mutex_);
  const double wait = std::max(0.0, deadline - now());
  return cv_.wait_for(lock, std::chrono::duration<double>(wait), [&] { return !inbox_.empty(); });
}

int WorldHost::run() {
  reanchor();
  if (runs_away_alone())
    spdlog::warn("--speed max with no --until: the files this server writes grow as fast as the world runs "
                 "(hundreds of MB a minute for a gas), whether or not anyone is connected; it pauses when the last "
                 "client leaves. Give --until T to bound the run");
  if (options_.until && server_->time() >= *options_.until) {
    stopping_ = true;
    stop_reason_ = "until";
  }
  while (!stopping_) {
    drain_inbox();
    if (stopping_) break;
    do_file_requests();
    const double t_now = now();
    send_due_frames(t_now);
    double deadline = t_now + 0.5;
    for (const auto& [key, s] : streams_) deadline = std::min(deadline, s.next_due);
    if (ended_ || (paused_ && steps_left_ == 0)) {
      wait_inbox_until(deadline);
      continue;
    }
    double target = server_->world().dt() > 0.0 ? static_cast<double>(server_->step() + 1) * scene_.def.dt : 0.0;
    if (options_.replay && !replay_target(target)) {  // at an end of the recording: it pauses there
      paused_ = true;
      steps_left_ = 0;
      broadcast_status();
      continue;
    }
    if (options_.until && target > *options_.until) target = *options_.until;
    if (speed_ > 0.0 && steps_left_ == 0) {
      const double due = anchor_wall_ + std::abs(target - anchor_sim_) / speed_;
      if (t_now < due) {
        wait_inbox_until(std::min(deadline, due));
        continue;
      }
      if (t_now - due > 0.25) {  // behind: go on from now rather than catch up in a burst
        anchor_wall_ = t_now;
        anchor_sim_ = target;
      }
    }
    step_end_ = server_->step() + 1;
    if (options_.replay && target < server_->time()) seek(target);
    else step_world(target);
    bool changed = false;
    if (steps_left_ > 0 && --steps_left_ == 0) changed = true;
    if (pause_at_ && server_->time() >= *pause_at_) {
      paused_ = true;
      pause_at_.reset();
      changed = true;
    }
    if (changed && !ended_) broadcast_status();
    if (options_.until && server_->time() >= *options_.until) {
      stopping_ = true;
      stop_reason_ = "until";
    }
  }
  // Stopped at a control boundary: flush the logs, tell every client, close.
  fan_out_events();
  if (events_file_) events_file_->flush();
  if (inputs_file_) inputs_file_->flush();
  check_outputs();
  if (recorder_) finish_recording(stop_reason_ == "until" ? "" : stop_reason_);
  const std::string bye = dump({{"type", "bye"}, {"reason", stop_reason_}, {"t", server_->time()}});
  for (auto& [id, c] : clients_) {
    c.client->send(std::make_shared<const std::string>(bye));
    c.client->close_after_send();
  }
  spdlog::info("stopped at t={} ({})", fmt(server_->time()), stop_reason_);
  if (on_finished) on_finished();
  return output_error_.empty() ? 0 : 1;
}

bool WorldHost::runs_away_alone() const {
  const bool files = !options_.events_path.empty() || !options_.inputs_path.empty() || !options_.record_path.empty();
  return files && speed_ == 0.0 && !options_.until && !options_.replay && !ended_;
}

void WorldHost::step_world(double target) {
  in_step_ = true;
  try {
    advance(target);
  } catch (const std::exception& e) {
    in_step_ = false;
    fan_out_events();
    end_world(e.what());
    return;
  }
  in_step_ = false;
  fan_out_events();
}

void WorldHost::at_boundary(turtle::WorldServer& server, std::uint64_t step) {
  // A replay has no remote turtles and takes no changes; and its messages must wait for the main
  // loop: a seek handled here, inside run_until, would rebuild the world under it, and a state
  // request would see a seek's way rather than its end.
  if (options_.replay) return;
  drain_inbox();
  apply_changes(server, step);
}

void WorldHost::apply_changes(turtle::WorldServer& server, std::uint64_t step) {
  apply_takeovers(server, step);
  apply_wall_changes(server, step);
  apply_body_changes(server, step);
}

}  // namespace turtlegas::server
