// SPDX-License-Identifier: MIT
#include "turtlegas/formats/input_log.hpp"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include <nlohmann/json.hpp>

#include "turtlegas/formats/json_text.hpp"
#include "turtlegas/turtle/view.hpp"
#include "turtlegas/turtle/json_depth.hpp"

namespace turtlegas::formats {
namespace {

/// One input line: `{"step": N, MEMBERS}` and a newline, MEMBERS being JSON object members
/// (`"key": value, ...`). Every input_*_line is one.
std::string line(std::uint64_t step, std::string_view members) {
  std::string out = "{\"step\": ";
  out += std::to_string(step);
  out += ", ";
  out += members;
  out += "}\n";
  return out;
}

/// `{"step": N, "KEY": VALUE}`, VALUE being JSON text.
std::string line(std::uint64_t step, std::string_view key, std::string_view value) {
  std::string members;
  append_json_string(members, key);
  members += ": ";
  members += value;
  return line(step, members);
}

std::string json_string(std::string_view s) {
  std::string out;
  append_json_string(out, s);
  return out;
}

void append_point(std::string& out, sim::Vec2 p) {
  out += '[';
  append_number(out, p.x);
  out += ", ";
  append_number(out, p.y);
  out += ']';
}

}  // namespace

std::string input_header_line(std::string_view world_name, double dt) {
  std::string out = "{\"format\": ";
  append_json_string(out, input_log_format);
  out += ", \"world\": ";
  append_json_string(out, world_name);
  out += ", \"dt\": ";
  append_number(out, dt);
  out += "}\n";
  return out;
}

std::string input_command_line(std::uint64_t step, std::string_view turtle, const turtle::RemoteCommand& c) {
  std::string members = "\"turtle\": ";
  append_json_string(members, turtle);
  members += ", \"command\": ";
  append_json_string(members, turtle::to_string(c.kind));
  if (turtle::takes_amount(c.kind)) {
    members += ", \"amount\": ";
    append_number(members, c.amount);
  }
  const auto keys = turtle::steer_keys(c.kind);  // arc, drive, wheels
  for (std::size_t k = 0; k < keys.size(); ++k) {
    members += ", \"";
    members += keys[k];
    members += "\": ";
    append_number(members, c.steer[k]);
  }
  if (c.kind == turtle::RemoteCommand::Kind::pen_down)
    members += c.pen == turtle::PenMode::wall ? ", \"mode\": \"wall\"" : ", \"mode\": \"line\"";
  if (c.kind == turtle::RemoteCommand::Kind::sense || c.kind == turtle::RemoteCommand::Kind::camera) {
    members += ", \"sensor\": ";
    append_json_string(members, c.sensor);
  }
  return line(step, members);
}

std::string input_takeover_line(std::uint64_t step, std::string_view turtle) {
  return line(step, "takeover", json_string(turtle));
}

std::string input_wall_line(std::uint64_t step, const sim::WallDef& wall) {
  std::string v = "{\"id\": ";
  append_json_string(v, wall.id);
  v += ", \"from\": ";
  append_point(v, wall.from);
  v += ", \"to\": ";
  append_point(v, wall.to);
  v += '}';
  return line(step, "add_wall", v);
}

std::string input_spawn_line(std::uint64_t step, std::string_view kind, const nlohmann::json& entry) {
  std::string v = "{";
  append_json_string(v, kind);
  v += ": ";
  v += entry.dump();  // numbers as the shortest text that reads back to the same double
  v += '}';
  return line(step, "spawn", v);
}

std::string input_view_line(std::uint64_t step, std::string_view op, const nlohmann::json& view) {
  std::string v = "{\"op\": ";
  append_json_string(v, op);
  v += ", \"view\": ";
  v += view.dump();
  v += '}';
  return line(step, "view", v);
}

std::string input_while_waiting(std::string line, std::string_view turtle, std::size_t taken) {
  // Every line ends "}\n": the members go in before it.
  line.resize(line.size() - 2);
  line += ", \"waiting\": ";
  append_json_string(line, turtle);
  if (taken > 0) {
    line += ", \"taken\": ";
    line += std::to_string(taken);
  }
  line += "}\n";
  return line;
}

std::string input_remove_line(std::uint64_t step, std::string_view id) {
  return line(step, "remove", json_string(id));
}

std::string input_teleport_line(std::uint64_t step, std::string_view id, sim::Vec2 pos, std::optional<sim::Vec2> vel,
                                std::optional<double> heading) {
  std::string v = "{\"id\": ";
  append_json_string(v, id);
  v += ", \"pos\": ";
  append_point(v, pos);
  if (vel) {
    v += ", \"vel\": ";
    append_point(v, *vel);
  }
  if (heading) {
    v += ", \"heading\": ";
    append_number(v, *heading);
  }
  v += '}';
  return line(step, "teleport", v);
}

ReplayInput::ReplayInput(std::istream& in, const sim::WorldDef& def, std::string file, SpawnApplier spawn)
    : spawn_(std::move(spawn)), file_(std::move(file)) {
  for (const sim::TurtleDef& t : def.turtles) turtle_ids_.push_back(t.id);
  commands_.resize(turtle_ids_.size());
  auto index_of = [&](const std::string& id, std::size_t line, const char* key) {
    for (std::size_t i = 0; i < turtle_ids_.size(); ++i)
      if (turtle_ids_[i] == id) return i;
    throw std::invalid_argument(file_ + ":" + std::to_string(line) + ": /" + key + ": no turtle '" + id +
                                "' in the world; replay the log with the world it was recorded with");
  };
  std::string text;
  std::size_t line = 0;
  bool header = false;
  std::uint64_t last_step = 0;
  while (std::getline(in, text)) {
    ++line;
    if (text.empty()) continue;
    auto fail = [&](const std::string& why) {
      throw std::invalid_argument(file_ + ":" + std::to_string(line) + ": " + why);
    };
    if (const auto deep = turtle::json_too_deep(text)) fail(*deep);
    const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    if (!j.is_object()) fail("not a JSON object; an input log has one object per line (docs/protocol.md)");
    if (!header) {
      if (j.value("format", std::string()) != input_log_format)
        fail("/format: the first line must be {\"format\": \"turtlegas-inputs/1\", ...}");
      header = true;
      continue;
    }
    const auto s = j.find("step");
    if (s == j.end() || !s->is_number_unsigned()) fail("/step: a step number >= 0 is needed on every line");
    const std::uint64_t step = s->get<std::uint64_t>();
    if (step < last_step) fail("/step: steps must not decrease (" + std::to_string(step) + " after " + std::to_string(last_step) + ")");
    last_step = step;
    auto point = [](const nlohmann::json& p) { return sim::Vec2{p.at(0).get<double>(), p.at(1).get<double>()}; };
    auto change = [&](Change::Kind kind) {
      Change c;
      c.kind = kind;
      c.step = step;
      if (j.contains("waiting")) {
        c.waiting = index_of(j.at("waiting").get<std::string>(), line, "waiting");
        const auto taken = j.find("taken");
        if (taken != j.end() && !taken->is_number_unsigned()) fail("/taken: a count of commands >= 0");
        if (taken != j.end()) c.taken = taken->get<std::size_t>();
      }
      return c;
    };
    try {
      if (j.contains("turtle")) {
        const std::size_t i = index_of(j.at("turtle").get<std::string>(), line, "turtle");
        const auto kind = turtle::remote_command_kind(j.at("command").get<std::string>());
        if (!kind) fail("/command: not a command (forward, back, left, right, wait, yield, pen_up, pen_down, sense, arc, drive, wheels, camera)");
        turtle::RemoteCommand c;
        c.kind = *kind;
        if (turtle::takes_amount(c.kind)) {
          c.amount = j.at("amount").get<double>();
          if (!std::isfinite(c.amount) || c.amount < 0.0) fail("/amount: must be finite and >= 0");
        }
        const auto keys = turtle::steer_keys(c.kind);
        for (std::size_t k = 0; k < keys.size(); ++k) {
          c.steer[k] = j.at(std::string(keys[k])).get<double>();
          if (!std::isfinite(c.steer[k])) fail("/" + std::string(keys[k]) + ": must be finite");
        }
        if (c.kind == turtle::RemoteCommand::Kind::pen_down)
          c.pen = j.value("mode", std::string("line")) == "wall" ? turtle::PenMode::wall : turtle::PenMode::line;
        if (c.kind == turtle::RemoteCommand::Kind::sense || c.kind == turtle::RemoteCommand::Kind::camera)
          c.sensor = j.at("sensor").get<std::string>();
        commands_[i].push_back({step, c});
      } else if (j.contains("takeover")) {
        Change c = change(Change::Kind::takeover);
        c.turtle = index_of(j.at("takeover").get<std::string>(), line, "takeover");
        changes_.push_back(std::move(c));
      } else if (j.contains("spawn")) {
        const nlohmann::json& sp = j.at("spawn");
        if (!sp.is_object() || sp.size() != 1 || !(sp.contains("ball") || sp.contains("turtle")))
          fail("/spawn: must be {\"ball\": {...}} or {\"turtle\": {...}}, a world-file entry");
        if (!spawn_) fail("/spawn: this log spawns bodies, which this replay cannot apply");
        if (sp.contains("turtle")) {
          // Its commands follow under its id; its index is the next turtle's.
          turtle_ids_.push_back(sp.at("turtle").at("id").get<std::string>());
          commands_.resize(turtle_ids_.size());
        }
        Change c = change(Change::Kind::spawn);
        c.body = sp;
        changes_.push_back(std::move(c));
      } else if (j.contains("remove")) {
        Change c = change(Change::Kind::remove);
        c.id = j.at("remove").get<std::string>();
        changes_.push_back(std::move(c));
      } else if (j.contains("teleport")) {
        const nlohmann::json& tp = j.at("teleport");
        Change c = change(Change::Kind::teleport);
        c.id = tp.at("id").get<std::string>();
        c.pos = point(tp.at("pos"));
        if (tp.contains("vel")) c.vel = point(tp.at("vel"));
        if (tp.contains("heading")) c.heading = tp.at("heading").get<double>();
        if (c.vel.has_value() == c.heading.has_value())
          fail("/teleport: a ball's teleport has \"vel\", a turtle's \"heading\" (one of them)");
        changes_.push_back(std::move(c));
      } else if (j.contains("add_wall")) {
        const nlohmann::json& w = j.at("add_wall");
        Change c = change(Change::Kind::add_wall);
        c.wall.id = w.at("id").get<std::string>();
        c.wall.from = point(w.at("from"));
        c.wall.to = point(w.at("to"));
        changes_.push_back(std::move(c));
      } else if (j.contains("view")) {
        const nlohmann::json& v = j.at("view");
        const std::string op = v.at("op").get<std::string>();
        if (op != "open" && op != "change" && op != "close") fail("/view/op: must be \"open\", \"change\" or \"close\"");
        if (op == "close" ? !v.at("view").is_string() : !v.at("view").is_object())
          fail("/view/view: a view object to open or change, a view's id to close");
        Change c = change(Change::Kind::view);
        c.body = v;
        changes_.push_back(std::move(c));
      } else {
        fail("a line needs \"turtle\" (a command), \"takeover\", \"add_wall\", \"spawn\", \"remove\", \"teleport\" or \"view\"");
      }
    } catch (const nlohmann::json::exception& e) {
      fail(std::string("a field is missing or has the wrong type: ") + e.what());
    }
  }
  if (!header) throw std::invalid_argument(file_ + ": empty; an input log starts with {\"format\": \"turtlegas-inputs/1\", ...}");
}

void ReplayInput::apply_view(turtle::WorldServer& server, const nlohmann::json& v, std::uint64_t step) const {
  const std::string op = v.at("op").get<std::string>();
  try {
    if (op == "close") server.close_view(v.at("view").get<std::string>());
    else if (op == "open") server.open_view(turtle::parse_view(v.at("view")));
    else server.change_view(turtle::parse_view(v.at("view")));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(file_ + ": the view change recorded at step " + std::to_string(step) + " was refused (" +
                             e.what() + "); is this the log of this world?");
  }
}

void ReplayInput::apply(turtle::WorldServer& server, Change& c) const {
  switch (c.kind) {
    case Change::Kind::takeover: server.make_remote(c.turtle); break;
    case Change::Kind::add_wall: server.add_wall(c.wall); break;
    case Change::Kind::spawn: spawn_(server, c.body); break;
    case Change::Kind::remove: server.remove_body(c.id); break;
    case Change::Kind::teleport:
      if (c.vel) server.teleport_ball(c.id, c.pos, *c.vel);
      else server.teleport_turtle(c.id, c.pos, *c.heading);
      break;
    case Change::Kind::view: apply_view(server, c.body, c.step); break;
  }
}

void ReplayInput::at_boundary(turtle::WorldServer& server, std::uint64_t step) {
  server_ = &server;
  step_ = step;
  taken_.assign(commands_.size(), 0);
  // The boundary's own changes, up to the first one made while the world waited for a command
  // (next() makes that one, in its turtle's turn).
  while (!changes_.empty() && changes_.front().step <= step) {
    if (changes_.front().step < step)
      throw std::runtime_error(file_ + ": the change recorded at step " + std::to_string(changes_.front().step) +
                               " was not reached at that step; is this the log of this world?");
    if (changes_.front().waiting) break;
    Change c = std::move(changes_.front());
    changes_.pop_front();
    apply(server, c);
  }
}

std::optional<turtle::RemoteCommand> ReplayInput::next(std::uint64_t step, std::size_t turtle) {
  if (taken_.size() <= turtle) taken_.resize(turtle + 1, 0);
  // The changes made while the world waited for this turtle, at this point of the boundary.
  while (server_ && step == step_ && !changes_.empty() && changes_.front().step == step && changes_.front().waiting == turtle &&
         changes_.front().taken == taken_[turtle]) {
    Change c = std::move(changes_.front());
    changes_.pop_front();
    apply(*server_, c);
  }
  if (turtle >= commands_.size()) return std::nullopt;
  std::deque<Command>& q = commands_[turtle];
  if (q.empty() || q.front().step > step) return std::nullopt;
  if (q.front().step < step)
    throw std::runtime_error(file_ + ": turtle '" + turtle_ids_[turtle] + "' was not idle at step " +
                             std::to_string(q.front().step) + " where the log gives it a command; is this the log of this world?");
  const turtle::RemoteCommand c = q.front().command;
  q.pop_front();
  ++taken_[turtle];
  return c;
}

}  // namespace turtlegas::formats
