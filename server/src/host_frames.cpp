// SPDX-License-Identifier: MIT
// The world host's output to viewers: the events of a step fanned out to the event log, the
// recording and the subscribers; frames built once per stream and sent when due; subscribe,
// unsubscribe and snapshot (docs/protocol.md, "Frames"); a world that ends, told to everyone.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include <spdlog/spdlog.h>

#include "host_text.hpp"
#include "turtlegas/formats/event_log.hpp"
#include "turtlegas/server/protocol.hpp"
#include "turtlegas/server/world_host.hpp"

namespace turtlegas::server {

using nlohmann::json;

void WorldHost::fan_out_events() {
  if (events_.empty()) return;
  if (events_writer_) events_writer_->write(events_);
  if (recorder_) recorder_->events(events_);
  check_outputs();  // a full disk stops the server, named, rather than cut the logs silently
  bool wanted = false;
  for (const auto& [key, s] : streams_) wanted = wanted || s.kind().all_events || !s.kind().events.empty();
  if (wanted) {
    std::string line;
    for (const turtle::LogEvent& e : events_) {
      line.clear();
      formats::append_event(line, formats::event_line(e));
      if (!line.empty() && line.back() == '\n') line.pop_back();
      for (auto& [key, s] : streams_) s.add_event(e.kind, line, options_.limits.max_frame_events);
    }
  }
  events_.clear();
}

void WorldHost::end_world(const std::string& reason) {
  ended_ = reason;
  if (recorder_) finish_recording("ended: " + reason, false);
  spdlog::error("the world ended at t={}: {}", fmt(server_->time()), reason);
  // Changes waiting for a boundary that will not come are answered now.
  auto refuse = [&](std::uint64_t client, const json& id, const char* request) {
    auto it = clients_.find(client);
    if (it == clients_.end()) return;
    ++it->second.errors;
    reply_text(it->second, error_text("ended", "the world has ended (" + reason + ") before the change was made", &id, request));
  };
  for (const WallChange& w : wall_changes_) refuse(w.client, w.id, "add_wall");
  for (const Takeover& t : takeovers_) refuse(t.client, t.id, "claim");
  wall_changes_.clear();
  takeovers_.clear();
  refuse_body_changes(reason);
  broadcast_status();
}

std::vector<bool> WorldHost::claimed() const {
  std::vector<bool> out(slots_.size());
  for (std::size_t i = 0; i < slots_.size(); ++i) out[i] = slots_[i].owner != 0;
  return out;
}

FrameClock WorldHost::clock() const {
  FrameClock c;
  c.wall = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  c.paused = paused_ && steps_left_ == 0;
  c.speed = speed_ > 0.0 ? json(speed_) : json("max");
  return c;
}

void WorldHost::send_due_frames(double t_now) {
  if (streams_.empty()) return;
  std::map<std::string, std::vector<Client*>> members;
  for (auto& [id, c] : clients_)
    if (c.stream) members[*c.stream].push_back(c.client.get());
  const std::vector<bool> claims = claimed();
  for (auto it = streams_.begin(); it != streams_.end();) {
    auto m = members.find(it->first);
    if (m == members.end()) {
      it = streams_.erase(it);
      continue;
    }
    FrameStream& s = it->second;
    if (s.next_due <= t_now) {
      const std::shared_ptr<const std::string> frame = s.build(*server_, claims, clock());
      ++frames_built_;
      for (Client* c : m->second) c->send_frame(frame, s.kind().binary);
      s.next_due += 1.0 / s.kind().rate;
      if (s.next_due < t_now) s.next_due = t_now + 1.0 / s.kind().rate;
    }
    ++it;
  }
}

void WorldHost::on_subscribe(ClientState& c, const json& m, const std::string& /*type*/) {
  const json id = message_id(m);
  constexpr std::string_view ex = R"({"type": "subscribe", "rate": 30, "events": ["touch"], "format": "json"})";
  FrameKind k;
  if (auto r = optional_number(m, "rate", ex)) {
    if (!(*r > 0.0 && *r <= 120.0)) throw RequestError("bad_value", "/rate must be > 0 and <= 120 frames per second", "/rate");
    k.rate = *r;
  }
  if (m.contains("format")) {
    const std::string f = string_field(m, "format", ex);
    if (f != "json" && f != "binary") throw RequestError("bad_value", "/format must be \"json\" or \"binary\"", "/format");
    k.binary = f == "binary";
    if (k.binary && !c.client->binary_capable())
      throw RequestError("unsupported", "/format: binary frames need a WebSocket; TCP lines carry \"json\" frames", "/format");
  }
  if (auto v = optional_bool(m, "velocities", ex)) k.velocities = *v;
  if (auto r = m.find("region"); r != m.end()) {
    constexpr const char* why = "/region must be [x0, y0, x1, y1], four finite numbers with x0 < x1 and y0 < y1";
    if (!r->is_array() || r->size() != 4 || !std::all_of(r->begin(), r->end(), [](const json& x) { return x.is_number(); }))
      throw RequestError("wrong_type", why, "/region");
    std::array<double, 4> box{};
    for (std::size_t q = 0; q < 4; ++q) box[q] = (*r)[q].get<double>();
    if (!std::all_of(box.begin(), box.end(), [](double x) { return std::isfinite(x); }) || !(box[0] < box[2]) || !(box[1] < box[3]))
      throw RequestError("bad_value", why, "/region");
    k.region = box;
  }
  if (auto e = m.find("events"); e != m.end()) {
    if (e->is_string() && e->get<std::string>() == "all") {
      k.all_events = true;
    } else if (e->is_array()) {
      for (const json& x : *e) {
        if (!x.is_string()) throw RequestError("wrong_type", "/events must be \"all\" or an array of event kinds (strings), e.g. [\"touch\"]", "/events");
        k.events.push_back(x.get<std::string>());
      }
      std::sort(k.events.begin(), k.events.end());
      k.events.erase(std::unique(k.events.begin(), k.events.end()), k.events.end());
    } else {
      throw RequestError("wrong_type", "/events must be \"all\" or an array of event kinds (strings), e.g. [\"touch\"]", "/events");
    }
  }
  const std::string key = k.key();
  auto [sit, fresh] = streams_.try_emplace(key, k, *server_);
  if (fresh) sit->second.next_due = now();
  c.stream = key;
  json r = {{"type", "subscribed"}};
  if (!id.is_null()) r["id"] = id;
  r["rate"] = k.rate;
  r["events"] = k.all_events ? json("all") : json(k.events);
  r["format"] = k.binary ? "binary" : "json";
  r["velocities"] = k.velocities;
  if (k.region) r["region"] = *k.region;
  reply(c, r);
  reply_text(c, snapshot_text(*server_, ball_ids_, claimed(), clock(), nullptr, world_json()["arena"], looks_));
}

void WorldHost::on_unsubscribe(ClientState& c, const json& m, const std::string& /*type*/) {
  c.stream.reset();
  reply(c, ok(m, "unsubscribe"));
}

void WorldHost::on_snapshot(ClientState& c, const json& m, const std::string& /*type*/) {
  const json id = message_id(m);
  reply_text(c, snapshot_text(*server_, ball_ids_, claimed(), clock(), id, world_json()["arena"], looks_));
}

}  // namespace turtlegas::server
