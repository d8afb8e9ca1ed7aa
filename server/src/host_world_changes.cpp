// SPDX-License-Identifier: MIT
// The protocol's world changes (docs/protocol.md, "World changes"): add_wall, spawn, remove and
// teleport. add_wall is checked for its fields on arrival and placed at the next boundary. Spawn,
// remove and teleport are read and checked
// when they arrive (a bad entry, an unknown body, a turtle another connection has claimed are
// answered at once), applied at the next control boundary (WorldServer::spawn_ball and the
// others, which check the placement), recorded in the input log and answered `ok` or `refused`.
#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "host_text.hpp"
#include "turtlegas/formats/input_log.hpp"
#include "turtlegas/server/protocol.hpp"
#include "turtlegas/server/world_host.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/world/entries.hpp"
#include "turtlegas/world/file_error.hpp"

namespace turtlegas::server {

using nlohmann::json;

namespace {

constexpr std::string_view kSpawnBall =
    R"({"type": "spawn", "ball": {"id": "b-new", "pos": [100, 100], "vel": [20, 0], "radius": 4}})";
constexpr std::string_view kRemove = R"({"type": "remove", "body": "b-new"})";
constexpr std::string_view kTeleport = R"({"type": "teleport", "body": "t1", "pos": [200, 100], "heading": 90})";

}  // namespace

void WorldHost::queue_body_change(ClientState& c, const json& m, const std::string& type) {
  require_live();
  BodyChange change;
  change.client = c.client->id;
  change.id = m.contains("id") ? m.at("id") : json(nullptr);
  change.type = type;
  if (type == "spawn") {
    const bool ball = m.contains("ball"), turtle = m.contains("turtle");
    if (ball == turtle)
      throw RequestError(ball ? "bad_value" : "missing_field",
                         "a spawn has either \"ball\" or \"turtle\", a world-file entry; send e.g. " + std::string(kSpawnBall),
                         ball ? "/turtle" : "/ball");
    const char* key = ball ? "ball" : "turtle";
    // Read now, as a world file's entry (its errors at once); placed at the boundary.
    try {
      std::optional<std::string> problem;
      if (ball) {
        const sim::BallDef d = world::read_ball_entry(m.at(key), "spawn");
        problem = server_->placement_problem(d.pos, d.radius);
      } else {
        const world::TurtleEntry t = world::read_turtle_entry(m.at(key), "spawn", registry_);
        if (t.program.builder)
          throw RequestError("refused", "/turtle: a builder (a wall pen) is set up before the run; put it in the world file",
                             "/turtle");
        problem = server_->placement_problem(t.body.pos, t.body.radius);
      }
      // What it would overlap now is refused now (the boundary checks again, for what moved since).
      if (problem) throw RequestError("refused", std::string("/") + key + ": " + *problem, std::string("/") + key);
    } catch (const world::WorldFileError& e) {
      const std::string field = std::string("/") + key + e.json_path;
      throw RequestError("bad_value", field + ": " + e.reason, field);
    }
    change.spawn = json{{key, m.at(key)}};
    change.body = m.at(key).value("id", std::string());
  } else {
    const std::string_view ex = type == "remove" ? kRemove : kTeleport;
    change.body = string_field(m, "body", ex);
    const std::optional<bool> ball = server_->body_is_ball(change.body);
    if (!ball)
      throw RequestError("unknown_body", "/body: no ball or turtle '" + change.body.substr(0, 64) + "' is in this world", "/body");
    change.ball = *ball;
    if (!*ball) {
      // A turtle another connection drives is theirs to move or end.
      std::size_t i = 0;
      while (scene_.def.turtles[i].id != change.body) ++i;
      if (slots_[i].owner != 0 && slots_[i].owner != c.client->id)
        throw RequestError("claimed", "/body: '" + change.body + "' is claimed by another connection; only it may " + type + " it",
                           "/body");
    }
    if (type == "teleport") {
      change.pos = point_field(m, "pos", "", ex);
      // (A body in a collision category of its own is measured at the boundary only.)
      double radius = 0.0;
      bool plain = false;
      const sim::WorldDef& now = server_->scene();
      for (const sim::BallDef& d : now.balls)
        if (d.id == change.body) radius = d.radius, plain = d.layers == sim::Layers{};
      for (const sim::TurtleDef& d : now.turtles)
        if (d.id == change.body) radius = d.radius, plain = d.layers == sim::Layers{};
      if (plain)
        if (auto problem = server_->placement_problem(change.pos, radius, change.body))
          throw RequestError("refused", "/pos: " + *problem, "/pos");
      if (*ball) {
        if (m.contains("heading")) throw RequestError("bad_value", "/heading: a ball has no heading; give \"vel\"", "/heading");
        if (m.contains("vel")) change.vel = point_field(m, "vel", "", ex);
      } else {
        if (m.contains("vel")) throw RequestError("bad_value", "/vel: a turtle's velocity comes from its commands; give \"heading\"", "/vel");
        change.heading = optional_number(m, "heading", ex);
      }
    }
  }
  body_changes_.push_back(std::move(change));
}

std::size_t WorldHost::spawn_into_scene(turtle::WorldServer& server, const nlohmann::json& entry, const std::string& source) {
  // The world grows by the body, and so do the host's scene, ids and slots, so that frames name it.
  const std::size_t index = world::spawn_entry(server, entry, source, registry_);
  const sim::WorldDef& now = server.scene();
  if (entry.contains("ball")) {
    scene_.def.balls.push_back(now.balls[index]);
    ball_ids_.push_back(now.balls[index].id);
  } else {
    scene_.def.turtles.push_back(now.turtles[index]);
    scene_.programs.push_back(world::read_turtle_entry(entry.at("turtle"), source, registry_).program);
    slots_.push_back(Slot{});
  }
  return index;
}

void WorldHost::apply_body_changes(turtle::WorldServer& server, std::uint64_t step) {
  while (!body_changes_.empty()) {
    BodyChange b = std::move(body_changes_.front());
    body_changes_.pop_front();
    auto it = clients_.find(b.client);
    const json m = {{"id", b.id}};
    json reply_msg;
    try {
      if (b.type == "spawn") {
        const bool ball = b.spawn.contains("ball");
        const std::size_t index = spawn_into_scene(server, b.spawn, "spawn");
        write_input(formats::input_spawn_line(step, ball ? "ball" : "turtle", b.spawn.at(ball ? "ball" : "turtle")));
        reply_msg = ok(m, "spawn");
        reply_msg.update({{"body", b.body}, {"kind", ball ? "ball" : "turtle"}, {"index", index}});
      } else if (b.type == "remove") {
        if (!b.ball) {
          std::size_t i = 0;
          while (scene_.def.turtles[i].id != b.body) ++i;
          Slot& s = slots_[i];
          if (s.owner != 0 && s.owner != b.client)
            throw std::invalid_argument("'" + b.body + "' was claimed by another connection meanwhile");
          if (s.owner != 0)
            if (auto owner = clients_.find(s.owner); owner != clients_.end() && owner->second.claims > 0) --owner->second.claims;
          s = Slot{};
        }
        server.remove_body(b.body);
        write_input(formats::input_remove_line(step, b.body));
        reply_msg = ok(m, "remove");
        reply_msg["body"] = b.body;
      } else {  // teleport
        std::optional<sim::Vec2> vel;
        std::optional<double> heading;
        if (b.ball) {
          std::size_t i = 0;
          while (scene_.def.balls[i].id != b.body) ++i;
          vel = b.vel ? *b.vel : server.world().ball(i).vel;  // kept: recorded as it is now
          server.teleport_ball(b.body, b.pos, *vel);
        } else {
          std::size_t i = 0;
          while (scene_.def.turtles[i].id != b.body) ++i;
          if (slots_[i].owner != 0 && slots_[i].owner != b.client)
            throw std::invalid_argument("'" + b.body + "' was claimed by another connection meanwhile");
          heading = b.heading ? *b.heading : sim::to_degrees(server.turtle_status(i).state.heading);
          server.teleport_turtle(b.body, b.pos, *heading);
        }
        write_input(formats::input_teleport_line(step, b.body, b.pos, vel, heading));
        reply_msg = ok(m, "teleport");
        reply_msg["body"] = b.body;
      }
    } catch (const world::WorldFileError& e) {
      if (it == clients_.end()) continue;
      ++it->second.errors;
      reply_text(it->second, error_text("bad_value", e.json_path + ": " + e.reason, &b.id, b.type, e.json_path));
      continue;
    } catch (const std::invalid_argument& e) {
      if (it == clients_.end()) continue;
      ++it->second.errors;
      reply_text(it->second, error_text("refused", e.what(), &b.id, b.type, b.type == "spawn" ? "" : "/body"));
      continue;
    }
    if (it != clients_.end()) reply(it->second, reply_msg);
  }
}

void WorldHost::refuse_body_changes(const std::string& reason) {
  for (const BodyChange& b : body_changes_) {
    auto it = clients_.find(b.client);
    if (it == clients_.end()) continue;
    ++it->second.errors;
    reply_text(it->second, error_text("ended", "the world has ended (" + reason + ") before the change was made", &b.id, b.type));
  }
  body_changes_.clear();
}

void WorldHost::on_add_wall(ClientState& c, const json& m, const std::string& /*type*/) {
  const json id = message_id(m);
  require_live();
  constexpr std::string_view ex = R"({"type": "add_wall", "wall": {"id": "w-new", "from": [100, 300], "to": [200, 300]}})";
  const auto w = m.find("wall");
  if (w == m.end()) throw RequestError("missing_field", "/wall is missing; send e.g. " + std::string(ex), "/wall");
  if (!w->is_object()) throw RequestError("wrong_type", "/wall must be an object; send e.g. " + std::string(ex), "/wall");
  WallChange change{c.client->id, id, {}};
  const auto wid = w->find("id");
  if (wid == w->end()) throw RequestError("missing_field", "/wall/id is missing: a wall needs an id no body has; send e.g. " + std::string(ex), "/wall/id");
  if (!wid->is_string() || wid->get_ref<const std::string&>().empty() || wid->get_ref<const std::string&>().size() > 200)
    throw RequestError("wrong_type", "/wall/id must be a non-empty string of at most 200 characters", "/wall/id");
  change.wall.id = wid->get<std::string>();
  change.wall.from = point_field(*w, "from", "/wall", ex);
  change.wall.to = point_field(*w, "to", "/wall", ex);
  wall_changes_.push_back(std::move(change));
  // answered at the next boundary
}

void WorldHost::apply_wall_changes(turtle::WorldServer& server, std::uint64_t step) {
  while (!wall_changes_.empty()) {
    WallChange w = std::move(wall_changes_.front());
    wall_changes_.pop_front();
    auto it = clients_.find(w.client);
    try {
      server.add_wall(w.wall);
      write_input(formats::input_wall_line(step, w.wall));
      if (it != clients_.end()) {
        json m = {{"id", w.id}};
        reply(it->second, ok(m, "add_wall"));
      }
    } catch (const std::invalid_argument& e) {
      if (it != clients_.end()) {
        ++it->second.errors;
        reply_text(it->second, error_text("refused", std::string("/wall: ") + e.what(), &w.id, "add_wall", "/wall"));
      }
    }
  }
}

}  // namespace turtlegas::server
