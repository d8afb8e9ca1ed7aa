// SPDX-License-Identifier: MIT
// The world host's replies: sending to one client or all, the status and world objects every
// reply and welcome carries, `ok`, and the checks a request's handler starts with.
#include <string>

#include "host_text.hpp"
#include "turtlegas/server/protocol.hpp"
#include "turtlegas/server/world_host.hpp"
#include "turtlegas/sim/mode_names.hpp"

namespace turtlegas::server {

using nlohmann::json;

void WorldHost::reply(ClientState& c, const json& message) { reply_text(c, dump(message)); }

void WorldHost::reply_text(ClientState& c, std::string text) {
  c.client->send(std::make_shared<const std::string>(std::move(text)));
}

void WorldHost::broadcast(const std::string& text) {
  const auto shared = std::make_shared<const std::string>(text);
  for (auto& [id, c] : clients_)
    if (c.hello) c.client->send(shared);
}

void WorldHost::broadcast_status() { broadcast(dump({{"type", "status"}, {"status", status_json()}})); }

json WorldHost::status_json() const {
  json st = {{"t", server_->time()},
          {"step", server_->step()},
          {"paused", paused_ && steps_left_ == 0},
          {"speed", speed_ > 0.0 ? json(speed_) : json("max")},
          {"until", pause_at_ ? json(*pause_at_) : json(nullptr)},
          {"ended", ended_ ? json(*ended_) : json(nullptr)}};
  if (options_.replay)
    st["replay"] = {{"end", options_.replay->end}, {"reverse", reverse_}, {"complete", options_.replay->complete}};
  return st;
}

json WorldHost::sensors_json(std::size_t i) const {
  json sensors = json::array();
  for (const turtle::SensorArc& a : scene_.programs[i].sensors) sensors.push_back(a.name);
  return sensors;
}

json WorldHost::senses_json(std::size_t i) const {
  json senses = json::array();  // range sensors: the viewer draws their rays (docs/viewer.md)
  for (const turtle::RangeSensor& r : scene_.programs[i].senses) {
    json s = {{"name", r.name}, {"bearings", r.bearings}, {"range", r.range}};
    if (r.camera) s["camera"] = true;  // its pixels' bearings; read with the `camera` message
    senses.push_back(std::move(s));
  }
  return senses;
}

json WorldHost::claimed_reply(const json& id, std::size_t i, bool takeover, double t, std::uint64_t step) const {
  json r = {{"type", "claimed"}};
  if (!id.is_null()) r["id"] = id;
  r.update({{"turtle", scene_.def.turtles[i].id}, {"index", i}, {"sensors", sensors_json(i)},
            {"senses", senses_json(i)}, {"takeover", takeover}, {"t", t}, {"step", step}});
  return r;
}

json WorldHost::world_json() const {
  const sim::WorldDef& def = scene_.def;
  json turtles = json::array();
  for (std::size_t i = 0; i < server_->turtle_count(); ++i) {
    const json sensors = sensors_json(i), senses = senses_json(i);
    turtles.push_back({{"id", def.turtles[i].id},
                       {"index", i},
                       {"controller", server_->controller(i)},
                       {"remote", server_->is_remote(i)},
                       {"claimed", slots_[i].owner != 0},
                       {"radius", server_->world().turtle_radius(i)},
                       {"sensors", sensors},
                       {"senses", senses}});
  }
  return {{"name", def.name},
          {"arena", {{"width", def.arena.width}, {"height", def.arena.height}, {"boundary", std::string(sim::to_string(def.arena.boundary))}}},
          {"dt", def.dt},
          {"mode", sim::to_string(options_.mode)},
          {"remote", options_.realtime ? "realtime" : "lockstep"},
          {"balls", server_->world().ball_count()},
          {"walls", server_->world().walls().size()},
          {"turtles", turtles},
          // The world file's "colour" keys, by body id, as "#rrggbb" (what cameras see; the viewer
          // draws those bodies in them). Bodies without one are not listed.
          {"colours", server_->colours().by_id},
          {"views", views_json(*server_)}};
}

json WorldHost::ok(const json& m, const char* request) const {
  json r = {{"type", "ok"}};
  if (auto it = m.find("id"); it != m.end() && !it->is_null()) r["id"] = *it;
  r["request"] = request;
  r["status"] = status_json();
  return r;
}

std::size_t WorldHost::turtle_index(const json& m, const char* example) const {
  const std::string id = string_field(m, "turtle", example);
  for (std::size_t i = 0; i < scene_.def.turtles.size(); ++i)
    if (scene_.def.turtles[i].id == id) return i;
  std::string known;
  for (const sim::TurtleDef& t : scene_.def.turtles) known += (known.empty() ? "" : ", ") + t.id;
  throw RequestError("unknown_turtle", "/turtle: no turtle '" + id + "' in this world (turtles: " +
                                           (known.empty() ? "none" : known) + ")",
                     "/turtle");
}

void WorldHost::require_live() const {
  if (ended_)
    throw RequestError("ended", "the world has ended (" + *ended_ + "); `load` a world to go on");
}

}  // namespace turtlegas::server
