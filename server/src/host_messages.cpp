// SPDX-License-Identifier: MIT
// The world host's dispatch: one table of the protocol's messages (docs/protocol.md), each with
// who may send it and its handler. The table is the one list of message names: an unknown type is
// answered with it, and nothing else lists them. The checks before a handler, in this order: a
// JSON object with a string "type" and a fit "id"; a known type; hello first; the token (or
// loopback for frames); not a replay, for what would change the world.
#include <algorithm>
#include <array>
#include <string>

#include <spdlog/spdlog.h>

#include "host_text.hpp"
#include "turtlegas/server/protocol.hpp"
#include "turtlegas/server/world_host.hpp"

namespace turtlegas::server {

using nlohmann::json;

/// Who may send a message.
enum class WorldHost::Access {
  anyone,      ///< hello: before the hello too
  greeted,     ///< after the hello, with or without the token
  viewer,      ///< frames: the token, or a loopback peer
  controller,  ///< the token (every connection when the server has none)
};

struct WorldHost::Handler {
  std::string_view name;
  Access access;
  bool in_replay;  ///< false: refused in a replay (it would change the world), before the handler runs
  void (WorldHost::*handle)(ClientState& c, const json& m, const std::string& type);
};

std::span<const WorldHost::Handler> WorldHost::handlers() {
  using A = Access;
  // In docs/protocol.md's order (an unknown type's error lists them so).
  static constexpr std::array<Handler, 37> table = {{
      {"hello", A::anyone, true, &WorldHost::on_hello},
      {"subscribe", A::viewer, true, &WorldHost::on_subscribe},
      {"unsubscribe", A::viewer, true, &WorldHost::on_unsubscribe},
      {"snapshot", A::viewer, true, &WorldHost::on_snapshot},
      {"pause", A::controller, true, &WorldHost::on_pacing},
      {"resume", A::controller, true, &WorldHost::on_pacing},
      {"step", A::controller, true, &WorldHost::on_pacing},
      {"speed", A::controller, true, &WorldHost::on_pacing},
      {"run_until", A::controller, true, &WorldHost::on_pacing},
      {"claim", A::controller, false, &WorldHost::on_claim},
      {"release", A::controller, false, &WorldHost::on_release},
      {"forward", A::controller, false, &WorldHost::on_command},
      {"back", A::controller, false, &WorldHost::on_command},
      {"left", A::controller, false, &WorldHost::on_command},
      {"right", A::controller, false, &WorldHost::on_command},
      {"wait", A::controller, false, &WorldHost::on_command},
      {"yield", A::controller, false, &WorldHost::on_command},
      {"pen", A::controller, false, &WorldHost::on_command},
      {"sense", A::controller, false, &WorldHost::on_command},
      {"camera", A::controller, false, &WorldHost::on_command},
      {"arc", A::controller, false, &WorldHost::on_command},
      {"drive", A::controller, false, &WorldHost::on_command},
      {"wheels", A::controller, false, &WorldHost::on_command},
      {"add_wall", A::controller, false, &WorldHost::on_add_wall},
      {"save", A::controller, false, &WorldHost::on_file},
      {"load", A::controller, false, &WorldHost::on_file},
      {"spawn", A::controller, true, &WorldHost::queue_body_change},
      {"remove", A::controller, true, &WorldHost::queue_body_change},
      {"teleport", A::controller, true, &WorldHost::queue_body_change},
      {"view_open", A::controller, true, &WorldHost::handle_view_message},
      {"view_change", A::controller, true, &WorldHost::handle_view_message},
      {"view_close", A::controller, true, &WorldHost::handle_view_message},
      {"ping", A::greeted, true, &WorldHost::on_ping},
      {"stats", A::greeted, true, &WorldHost::on_stats},
      {"play", A::controller, true, &WorldHost::on_replay_control},
      {"seek", A::controller, true, &WorldHost::on_replay_control},
      {"reverse", A::controller, true, &WorldHost::on_replay_control},
  }};
  return table;
}

void WorldHost::handle(Inbound& in) {
  switch (in.kind) {
    case Inbound::Kind::connect: {
      ClientState c;
      c.client = in.client;
      c.authorized = !options_.token;
      clients_.emplace(in.client->id, std::move(c));
      return;
    }
    case Inbound::Kind::disconnect: {
      auto it = clients_.find(in.client->id);
      if (it == clients_.end()) return;
      release_all(it->second, "disconnected");
      clients_.erase(it);
      if (clients_.empty() && runs_away_alone()) {
        // Nobody watches, and the files would grow without bound: `serve --speed max --record R`
        // wrote 240 MB in 10 s after its client left. A client's `resume` goes on.
        paused_ = true;
        steps_left_ = 0;
        pause_at_.reset();
        spdlog::warn("the last client left at t = {} s: paused (at --speed max with no --until the files written would "
                     "grow without bound); a client's resume goes on",
                     fmt(server_->time()));
      }
      return;
    }
    case Inbound::Kind::state: {
      in.state_done(state_text());
      return;
    }
    case Inbound::Kind::stop:
      stopping_ = true;
      stop_reason_ = in.reason;
      return;
    case Inbound::Kind::message: break;
  }
  auto it = clients_.find(in.client->id);
  if (it == clients_.end()) return;  // it went away meanwhile
  ClientState& c = it->second;
  ++c.messages;
  try {
    handle_message(c, in.message);
  } catch (const RequestError& e) {
    ++c.errors;
    reply_text(c, error_reply(in.message, e));
  }
}

void WorldHost::handle_message(ClientState& c, const json& m) {
  if (!m.is_object()) throw RequestError("not_object", "a message is a JSON object with a \"type\", e.g. {\"type\": \"hello\", \"protocol\": \"turtlegas/1\"}");
  check_id(m);
  const auto type_it = m.find("type");
  if (type_it == m.end())
    throw RequestError("missing_field", "/type is missing: every message has a \"type\", e.g. {\"type\": \"ping\"}", "/type");
  if (!type_it->is_string())
    throw RequestError("wrong_type", "/type must be a string, e.g. {\"type\": \"ping\"}", "/type");
  const std::string& type = type_it->get_ref<const std::string&>();
  const std::span<const Handler> table = handlers();
  const auto h = std::find_if(table.begin(), table.end(), [&](const Handler& x) { return x.name == type; });
  if (h == table.end()) {
    std::string known;
    for (const Handler& x : table) known += (known.empty() ? "" : ", ") + std::string(x.name);
    throw RequestError("unknown_type", "/type: no message \"" + type.substr(0, 64) + "\" in turtlegas/1 (known: " + known + ")", "/type");
  }
  if (h->access != Access::anyone && !c.hello)
    throw RequestError("hello_first", "say hello first: {\"type\": \"hello\", \"protocol\": \"turtlegas/1\"}");
  const bool view = h->access == Access::viewer;
  if (h->access != Access::anyone && h->access != Access::greeted && (view ? !(c.authorized || c.client->loopback) : !c.authorized))
    throw RequestError("unauthorized", view ? "frames to a non-loopback peer need the token: send it in the hello"
                                            : "\"" + type + "\" needs the server's token: say hello with \"token\"");
  if (!h->in_replay) require_not_replay(type);
  (this->*(h->handle))(c, m, type);
}

void WorldHost::on_hello(ClientState& c, const json& m, const std::string& /*type*/) {
  const json id = message_id(m);
  constexpr std::string_view ex = R"({"type": "hello", "protocol": "turtlegas/1"})";
  const std::string protocol = string_field(m, "protocol", ex);
  if (protocol != protocol_name)
    throw RequestError("bad_protocol", "/protocol: this server speaks \"turtlegas/1\" (got \"" + protocol.substr(0, 64) + "\")", "/protocol");
  if (options_.token && m.contains("token")) {
    const std::string token = string_field(m, "token", R"({"type": "hello", "protocol": "turtlegas/1", "token": "T"})");
    if (!same_token(token, *options_.token)) {
      c.hello = true;
      throw RequestError("bad_token", "/token is not the server's token; the connection stays unauthorized (view only, from loopback)", "/token");
    }
    c.authorized = true;
  }
  c.hello = true;
  const Limits& l = options_.limits;
  json welcome = {{"type", "welcome"}};
  if (!id.is_null()) welcome["id"] = id;
  welcome["protocol"] = protocol_name;
  welcome["server"] = server_name;
  welcome["connection"] = c.client->id;
  welcome["authorized"] = c.authorized;
  welcome["world"] = world_json();
  welcome["status"] = status_json();
  welcome["capabilities"] = options_.replay ? json{"frames", "binary-frames", "control", "views", "replay"}
                                            : json{"frames", "binary-frames", "control", "remote", "add_wall", "spawn",
                                                   "remove", "teleport", "save", "load", "views"};
  welcome["limits"] = {{"max_message", l.max_message}, {"max_rate", l.max_rate}, {"max_claims", l.max_claims}, {"max_clients", l.max_clients}};
  reply(c, welcome);
}

void WorldHost::on_ping(ClientState& c, const json& m, const std::string& /*type*/) {
  const json id = message_id(m);
  json r = {{"type", "pong"}};
  if (!id.is_null()) r["id"] = id;
  r["t"] = server_->time();
  r["wall"] = clock().wall;
  reply(c, r);
}

void WorldHost::on_stats(ClientState& c, const json& m, const std::string& /*type*/) {
  const json id = message_id(m);
  json r = {{"type", "stats"}};
  if (!id.is_null()) r["id"] = id;
  r["connection"] = c.client->id;
  r["messages"] = c.messages;
  r["errors"] = c.errors + c.client->local_errors.load();
  r["frames_sent"] = c.client->frames_sent.load();
  r["frames_dropped"] = c.client->frames_dropped.load();
  r["bytes_sent"] = c.client->bytes_sent.load();
  r["frames_built"] = frames_built_;
  r["clients"] = clients_.size();
  reply(c, r);
}

}  // namespace turtlegas::server
