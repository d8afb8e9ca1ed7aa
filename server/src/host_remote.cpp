// SPDX-License-Identifier: MIT
// The world host's remote turtles (docs/protocol.md, "Remote controllers"): claim (a remote turtle
// at once; a takeover at the next boundary), release, the movement commands, and the runtime's side:
// next_command (in lockstep the world waits there for the owner's command, at most
// --lockstep-timeout) and on_report (results, touches, messages and faults to the owner).
#include <algorithm>
#include <stdexcept>
#include <string>

#include <spdlog/spdlog.h>

#include "host_text.hpp"
#include "turtlegas/formats/input_log.hpp"
#include "turtlegas/server/protocol.hpp"
#include "turtlegas/server/world_host.hpp"

namespace turtlegas::server {
namespace {

using nlohmann::json;

}  // namespace

class WorldHost::Input : public turtle::InputSource {
 public:
  explicit Input(WorldHost& host) : host_(host) {}
  void at_boundary(turtle::WorldServer& server, std::uint64_t step) override { host_.at_boundary(server, step); }
  std::optional<turtle::RemoteCommand> next(std::uint64_t step, std::size_t turtle) override {
    return host_.next_command(step, turtle);
  }

 private:
  WorldHost& host_;
};

std::shared_ptr<turtle::InputSource> WorldHost::remote_input() { return std::make_shared<Input>(*this); }

void WorldHost::release_all(ClientState& c, const char* why, const char* code, const std::string& message) {
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    Slot& s = slots_[i];
    if (s.owner != c.client->id) continue;
    s.owner = 0;
    if (s.queued) {  // accepted, not yet taken: dropped
      if (code) {
        ++c.errors;
        reply_text(c, error_text(code, message, &s.queued_id, {}, "/turtle"));
      }
      s.queued.reset();
      s.queued_id = nullptr;
      s.busy = false;
    }
    if (s.busy) {
      s.orphan = true;
      if (code && !s.inflight_id.is_null()) {  // its sender is told now; the result, when it comes, is dropped
        ++c.errors;
        reply_text(c, error_text(code, message, &s.inflight_id, {}, "/turtle"));
      }
    }
    spdlog::info("turtle '{}' released ({}, connection {}); it stands still", scene_.def.turtles[i].id, why, c.client->id);
  }
  std::erase_if(takeovers_, [&](const Takeover& t) { return t.client == c.client->id; });
  c.claims = 0;
}

void WorldHost::on_claim(ClientState& c, const json& m, const std::string& /*type*/) {
  const json id = message_id(m);
  require_live();
  constexpr std::string_view ex = R"({"type": "claim", "turtle": "t1"})";
  const std::size_t i = turtle_index(m, ex.data());
  const bool takeover = optional_bool(m, "takeover", ex).value_or(false);
  Slot& s = slots_[i];
  const std::string& tid = scene_.def.turtles[i].id;
  if (server_->turtle_status(i).gone)
    throw RequestError("unknown_turtle", "/turtle: '" + tid + "' is no longer in the world (removed, crushed or out of an open arena); claim a turtle that is", "/turtle");
  if (s.owner == c.client->id) throw RequestError("claimed", "/turtle: this connection has claimed '" + tid + "' already", "/turtle");
  if (s.owner != 0 || std::any_of(takeovers_.begin(), takeovers_.end(), [&](const Takeover& t) { return t.turtle == i; }))
    throw RequestError("claimed", "/turtle: '" + tid + "' is claimed by another connection; it is free again when that one releases it or closes", "/turtle");
  if (c.claims >= options_.limits.max_claims)
    throw RequestError("too_many_claims", "a connection may claim at most " + std::to_string(options_.limits.max_claims) + " turtles; release one first");
  if (server_->is_remote(i)) {
    s.owner = c.client->id;
    ++c.claims;
    reply(c, claimed_reply(id, i, false, server_->time(), server_->step()));
    return;
  }
  if (!takeover)
    throw RequestError("not_remote", "/turtle: '" + tid + "' runs the program '" + server_->controller(i) +
                                         "'; claim it with \"takeover\": true to detach that program, or make its controller \"remote\" in the world file",
                       "/turtle");
  ++c.claims;
  takeovers_.push_back({c.client->id, id, i});
  // answered at the next boundary
}

void WorldHost::on_release(ClientState& c, const json& m, const std::string& /*type*/) {
  const std::size_t i = turtle_index(m, R"({"type": "release", "turtle": "t1"})");
  Slot& s = slots_[i];
  if (s.owner != c.client->id)
    throw RequestError("not_claimed", "/turtle: this connection has not claimed '" + scene_.def.turtles[i].id + "'", "/turtle");
  s.owner = 0;
  if (s.queued) {
    s.queued.reset();
    s.busy = false;
  }
  if (s.busy) s.orphan = true;
  if (c.claims > 0) --c.claims;
  reply(c, ok(m, "release"));
}

void WorldHost::on_command(ClientState& c, const json& m, const std::string& type) {
  const json id = message_id(m);
  require_live();
  const std::string ex = "{\"type\": \"" + type + "\", \"turtle\": \"t1\"" +
                         (type == "pen" ? ", \"down\": true}" : type == "yield" ? "}" : type == "sense" ? ", \"sensor\": \"ir\"}"
                          : type == "camera" ? ", \"sensor\": \"cam\"}"
                          : type == "arc" ? ", \"radius\": 50, \"degrees\": 90}" : type == "drive" ? ", \"v\": 20, \"omega\": 45, \"seconds\": 2}"
                          : type == "wheels" ? ", \"left\": 20, \"right\": 10, \"seconds\": 2}" : ", \"amount\": 100}");
  const std::size_t i = turtle_index(m, ex.c_str());
  const turtle::RemoteCommand cmd = read_command(m, type);  // the message first, then the turtle's state
  Slot& s = slots_[i];
  const std::string& tid = scene_.def.turtles[i].id;
  if (server_->turtle_status(i).gone)
    throw RequestError("unknown_turtle", "/turtle: '" + tid + "' is no longer in the world (removed, crushed or out of an open arena)", "/turtle");
  if (s.owner != c.client->id)
    throw RequestError("not_claimed", "/turtle: claim '" + tid + "' first: {\"type\": \"claim\", \"turtle\": \"" + tid + "\"}", "/turtle");
  const bool camera = cmd.kind == turtle::RemoteCommand::Kind::camera;
  if ((cmd.kind == turtle::RemoteCommand::Kind::sense || camera) && i < scene_.programs.size()) {
    // Refused here rather than faulting the turtle's program, as Turtle::scan (camera) would throw.
    std::string names;
    bool found = false;
    for (const turtle::RangeSensor& r : scene_.programs[i].senses) {
      if (camera && !r.camera) continue;
      found = found || r.name == cmd.sensor;
      names += (names.empty() ? "" : ", ") + r.name;
    }
    if (!found)
      throw RequestError("bad_value", "/sensor: '" + tid + "' has no " + (camera ? "camera" : "range sensor") + " \"" +
                                          cmd.sensor + "\"" +
                                          (names.empty() ? std::string("; declare it under the turtle's \"senses\" in the world file")
                                                         : (camera ? "; its cameras: " : "; its senses: ") + names),
                         "/sensor");
  }
  if (s.busy)
    throw RequestError("busy", "/turtle: '" + tid + "' has not finished its previous command; wait for its result", "/turtle");
  if (server_->turtle_status(i).finished)
    throw RequestError("refused", "/turtle: '" + tid + "' is parked for good (its program stopped: " + server_->turtle_status(i).fault + ")", "/turtle");
  s.queued = cmd;
  s.queued_id = id;
  s.busy = true;
  // answered by its result
}

void WorldHost::apply_takeovers(turtle::WorldServer& server, std::uint64_t step) {
  while (!takeovers_.empty()) {
    const Takeover t = takeovers_.front();
    takeovers_.pop_front();
    auto it = clients_.find(t.client);
    if (it == clients_.end()) continue;
    server.make_remote(t.turtle);
    write_input(formats::input_takeover_line(step, scene_.def.turtles[t.turtle].id));
    Slot& s = slots_[t.turtle];
    s = Slot{};
    s.owner = t.client;
    reply(it->second, claimed_reply(t.id, t.turtle, true, server.time(), step));
  }
}

std::optional<turtle::RemoteCommand> WorldHost::next_command(std::uint64_t step, std::size_t turtle) {
  drain_inbox();
  // (slots_[turtle] is looked up afresh after each change: a spawn grows slots_.)
  if (!slots_[turtle].queued && slots_[turtle].owner != 0 && !options_.realtime && !stopping_) {
    // The world waits here for the owner's command. A client may well wait for something else
    // first: the `ok` of an add_wall or spawn, a claim with takeover, a save. Those are made here
    // and now, at this boundary (recorded as made while waiting, so that a replay makes them at
    // the same point), so that no client's request waits for a boundary that waits for that
    // client. A load cannot be made inside a step: the wait ends (the turtle stands still until
    // the next boundary) and the load is done when the step is.
    waiting_ = turtle;
    const double deadline = now() + options_.lockstep_timeout;
    auto pending_load = [&] {
      return std::any_of(file_requests_.begin(), file_requests_.end(), [](const FileRequest& f) { return f.load; });
    };
    for (;;) {
      apply_changes(*server_, step);
      if (!file_requests_.empty() && !pending_load()) do_file_requests();  // saves only
      Slot& s = slots_[turtle];
      if (s.queued || s.owner == 0 || stopping_ || pending_load()) break;
      const double t = now();
      if (t >= deadline) {
        // The client that holds the world up loses its claims, not everyone their world: its
        // turtles stand still from here (docs/protocol.md, "Lockstep and real time").
        const std::string why = "lockstep timeout: turtle '" + scene_.def.turtles[turtle].id + "' (claimed by connection " +
                                std::to_string(s.owner) + ") sent no command for " + fmt(options_.lockstep_timeout) +
                                " s at t=" + fmt(server_->time()) +
                                "; this connection's claims are released and its turtles stand still. Answer every result "
                                "with a command, or serve with --realtime or a longer --lockstep-timeout";
        spdlog::warn("{}", why);
        auto it = clients_.find(s.owner);
        if (it == clients_.end()) {
          s.owner = 0;
          break;
        }
        ++it->second.errors;
        reply_text(it->second, error_text("lockstep_timeout", why));
        release_all(it->second, "lockstep timeout", "lockstep_timeout", why);
        break;
      }
      send_due_frames(t);
      double wake = deadline;
      for (const auto& [key, st] : streams_) wake = std::min(wake, st.next_due);
      wait_inbox_until(wake);
      drain_inbox();
    }
    waiting_.reset();
  }
  Slot& s = slots_[turtle];
  if (!s.queued) return std::nullopt;
  const turtle::RemoteCommand c = *s.queued;
  s.queued.reset();
  s.inflight_id = s.queued_id;
  s.queued_id = nullptr;
  write_input(formats::input_command_line(step, scene_.def.turtles[turtle].id, c));
  if (s.taken_step != step) s.taken = 0;
  s.taken_step = step;
  ++s.taken;
  return c;
}

void WorldHost::on_report(const turtle::RemoteReport& r) {
  Slot& s = slots_[r.turtle];
  json id = nullptr;
  bool deliver = s.owner != 0;
  if (r.kind == turtle::RemoteReport::Kind::result) {
    id = s.inflight_id;
    s.inflight_id = nullptr;
    s.busy = false;
    deliver = deliver && !s.orphan;
    s.orphan = false;
  } else if (r.kind == turtle::RemoteReport::Kind::fault) {
    s.busy = false;
    s.orphan = false;
  }
  if (!deliver) return;
  auto it = clients_.find(s.owner);
  if (it == clients_.end()) return;
  reply_text(it->second, report_text(r, scene_.def.turtles[r.turtle].id, id));
}

}  // namespace turtlegas::server
