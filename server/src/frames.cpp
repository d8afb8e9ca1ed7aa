// SPDX-License-Identifier: MIT
#include "turtlegas/server/frames.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "turtlegas/formats/json_text.hpp"
#include "turtlegas/server/protocol.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/turtle/view.hpp"

namespace turtlegas::server {
namespace {

using formats::append_json_string;
using formats::append_number;

void append_point(std::string& out, sim::Vec2 p) {
  if (turtle::is_trail_break(p)) {  // between two strokes of a trail
    out += "null";
    return;
  }
  out += '[';
  append_number(out, p.x);
  out += ", ";
  append_number(out, p.y);
  out += ']';
}

double heading_degrees(const sim::TurtleState& s) { return sim::wrap_degrees(sim::to_degrees(s.heading)); }

void append_clock(std::string& out, const turtle::WorldServer& server, const FrameClock& clock) {
  out += ", \"t\": ";
  append_number(out, server.time());
  out += ", \"step\": ";
  out += std::to_string(server.step());
  out += ", \"wall\": ";
  append_number(out, clock.wall);
  out += clock.paused ? ", \"paused\": true, \"speed\": " : ", \"paused\": false, \"speed\": ";
  out += clock.speed.dump();
  out += ", \"sim_events\": " + std::to_string(server.world().stats().events);  // for events/s
}

void append_walls(std::string& out, const turtle::WorldServer& server, std::size_t from) {
  const std::vector<sim::WallDef>& walls = server.world().walls();
  out += '[';
  for (std::size_t k = from; k < walls.size(); ++k) {
    if (k > from) out += ", ";
    out += "{\"id\": ";
    append_json_string(out, walls[k].id);
    out += ", \"from\": ";
    append_point(out, walls[k].from);
    out += ", \"to\": ";
    append_point(out, walls[k].to);
    // Collision layers (the viewer dashes a wall its view's turtle passes through), and the poses
    // and visibility of a moving wall, for the viewer to place it at a frame's t.
    out += ", \"layers\": [" + std::to_string(walls[k].layers.category) + ", " + std::to_string(walls[k].layers.mask) + "]";
    if (!walls[k].keys.empty()) {
      out += ", \"keys\": [";
      for (std::size_t q = 0; q < walls[k].keys.size(); ++q) {
        const sim::WallKey& key = walls[k].keys[q];
        out += q > 0 ? ", [" : "[";
        append_number(out, key.t);
        for (double x : {key.from.x, key.from.y, key.to.x, key.to.y}) {
          out += ", ";
          append_number(out, x);
        }
        out += ']';
      }
      out += ']';
    }
    if (!walls[k].visibility.empty()) {
      out += ", \"visibility\": [";
      for (std::size_t q = 0; q < walls[k].visibility.size(); ++q) {
        out += q > 0 ? ", [" : "[";
        append_number(out, walls[k].visibility[q].t);
        out += walls[k].visibility[q].visible ? ", true]" : ", false]";
      }
      out += ']';
    }
    out += '}';
  }
  out += ']';
}

/// The balls a frame of `kind` carries: all, or those in its region (the grid's region query,
/// O(cells touched + balls found); in a periodic arena a region may cross the seams).
std::vector<std::uint32_t> balls_in(const sim::World& world, const FrameKind& kind) {
  std::vector<std::uint32_t> out;
  if (!kind.region) return out;
  const auto [x0, y0, x1, y1] = *kind.region;
  world.balls_in_rect({x0, y0}, {x1, y1}, out);
  return out;
}

/// The balls object; with `indexed`, only the balls of `which` and their indices.
void append_balls(std::string& out, const sim::World& world, bool velocities, bool indexed = false,
                  const std::vector<std::uint32_t>& which = {}) {
  const std::size_t n = indexed ? which.size() : world.ball_count();
  auto index = [&](std::size_t k) { return indexed ? which[k] : k; };
  std::string dead;
  out += '{';
  if (indexed) {
    out += "\"index\": [";
    for (std::size_t k = 0; k < n; ++k) out += (k > 0 ? ", " : "") + std::to_string(which[k]);
    out += "], ";
  }
  out += "\"pos\": [";
  for (std::size_t k = 0; k < n; ++k) {
    const sim::BallState b = world.ball(index(k));
    if (k > 0) out += ", ";
    append_number(out, b.pos.x);
    out += ", ";
    append_number(out, b.pos.y);
    if (!b.alive) dead += (dead.empty() ? "" : ", ") + std::to_string(index(k));
  }
  out += ']';
  if (velocities) {
    out += ", \"vel\": [";
    for (std::size_t k = 0; k < n; ++k) {
      const sim::BallState b = world.ball(index(k));
      if (k > 0) out += ", ";
      append_number(out, b.alive ? b.vel.x : 0.0);
      out += ", ";
      append_number(out, b.alive ? b.vel.y : 0.0);
    }
    out += ']';
  }
  out += ", \"dead\": [" + dead + "]}";
}

void append_turtle_head(std::string& out, const turtle::WorldServer::TurtleInfo& info, bool claimed) {
  out += "{\"id\": ";
  append_json_string(out, info.id);
  out += ", \"pos\": ";
  append_point(out, info.state.pos);
  out += ", \"heading\": ";
  append_number(out, heading_degrees(info.state));
  out += ", \"pen\": \"";
  out += pen_name(info.pen_down, info.pen_mode);
  out += info.it ? "\", \"it\": true" : "\", \"it\": false";
  out += info.remote ? ", \"remote\": true" : ", \"remote\": false";
  out += claimed ? ", \"claimed\": true" : ", \"claimed\": false";
  out += info.finished ? ", \"finished\": true" : ", \"finished\": false";
  out += info.gone ? ", \"gone\": true" : ", \"gone\": false";
}

void append_points(std::string& out, const std::vector<sim::Vec2>& points) {
  out += '[';
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (k > 0) out += ", ";
    append_point(out, points[k]);
  }
  out += ']';
}

template <class T>
void put(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));  // the machine is little-endian (x86-64, aarch64): as documented
  out.append(b, sizeof(T));
}

}  // namespace

std::string FrameKind::key() const {
  std::string k = std::to_string(rate) + (binary ? "/b" : "/j") + (velocities ? "/v" : "/-") + (all_events ? "/all" : "/");
  for (const std::string& e : events) k += e + ",";
  if (region)
    for (double v : *region) k += "/" + std::to_string(v);
  return k;
}

bool FrameKind::wants(std::string_view event_kind) const {
  return all_events || std::binary_search(events.begin(), events.end(), event_kind);
}

std::string snapshot_text(const turtle::WorldServer& server, const formats::IdTable& ball_ids,
                          const std::vector<bool>& claimed, const FrameClock& clock, const nlohmann::json& id,
                          const nlohmann::json& arena, const std::vector<TurtleLook>& looks) {
  const sim::World& world = server.world();
  std::string out = "{\"type\": \"snapshot\"";
  if (!id.is_null()) out += ", \"id\": " + id.dump();
  append_clock(out, server, clock);
  out += ", \"arena\": " + arena.dump();
  out += ", \"walls\": ";
  append_walls(out, server, 0);
  out += ", \"balls\": {\"ids\": [";
  for (std::size_t i = 0; i < world.ball_count(); ++i) {
    if (i > 0) out += ", ";
    append_json_string(out, i < ball_ids.size() ? ball_ids[i] : std::string_view());
  }
  out += "], \"radius\": [";
  for (std::size_t i = 0; i < world.ball_count(); ++i) {
    if (i > 0) out += ", ";
    append_number(out, world.radius(i));
  }
  out += "], ";
  std::string balls;
  append_balls(balls, world, true);
  out += balls.substr(1);  // the rest of the balls object: pos, vel, dead
  out += ", \"turtles\": [";
  for (std::size_t i = 0; i < server.turtle_count(); ++i) {
    if (i > 0) out += ", ";
    const turtle::WorldServer::TurtleInfo info = server.turtle_status(i);
    append_turtle_head(out, info, i < claimed.size() && claimed[i]);
    out += ", \"radius\": ";
    append_number(out, world.turtle_radius(i));
    if (i < looks.size()) {
      out += ", \"layers\": [" + std::to_string(looks[i].layers.category) + ", " + std::to_string(looks[i].layers.mask) + "]";
      out += ", \"arcs\": [";
      for (std::size_t q = 0; q < looks[i].sensors.size(); ++q) {
        out += q > 0 ? ", [" : "[";
        append_number(out, looks[i].sensors[q].from);
        out += ", ";
        append_number(out, looks[i].sensors[q].to);
        out += ']';
      }
      out += ']';
    }
    out += ", \"trail\": ";
    append_points(out, server.trail_since(i, 0));
    out += '}';
  }
  out += "], \"views\": " + views_text(server) + "}";
  return out;
}

std::string views_text(const turtle::WorldServer& server) {
  std::string out = "[";
  for (const turtle::View& v : server.views()) out += (out.size() > 1 ? ", " : "") + turtle::view_json_text(v);
  return out + "]";
}

nlohmann::json views_json(const turtle::WorldServer& server) {
  nlohmann::json a = nlohmann::json::array();
  for (const turtle::View& v : server.views()) a.push_back(turtle::view_to_json(v));
  return a;
}

FrameStream::FrameStream(FrameKind kind, const turtle::WorldServer& server) : kind_(std::move(kind)) {
  trail_sent_.resize(server.turtle_count());
  for (std::size_t i = 0; i < trail_sent_.size(); ++i) trail_sent_[i] = server.trail_size(i);
  walls_sent_ = server.world().walls().size();
  views_sent_ = server.views_revision();  // the snapshot that follows a subscribe has them
}

void FrameStream::add_event(std::string_view event_kind, std::string_view line, std::size_t max_events) {
  if (!kind_.wants(event_kind)) return;
  if (event_count_ >= max_events) {
    ++events_dropped_;
    return;
  }
  if (event_count_ > 0) events_ += ", ";
  events_.append(line);
  ++event_count_;
}

std::shared_ptr<const std::string> FrameStream::build(const turtle::WorldServer& server, const std::vector<bool>& claimed,
                                                      const FrameClock& clock) {
  ++built;
  const sim::World& world = server.world();
  // The parts JSON and binary frames share: new trail points and walls, and the events.
  std::string trails = "[";
  if (trail_sent_.size() < server.turtle_count()) trail_sent_.resize(server.turtle_count(), 0);  // spawned since
  std::vector<std::size_t> from(server.turtle_count());
  std::vector<std::vector<sim::Vec2>> points(server.turtle_count());
  for (std::size_t i = 0; i < server.turtle_count(); ++i) {
    from[i] = std::min(trail_sent_[i], server.trail_size(i));
    points[i] = server.trail_since(i, from[i]);
    trail_sent_[i] = from[i] + points[i].size();
  }
  const std::size_t walls_from = walls_sent_;
  walls_sent_ = world.walls().size();
  std::string tail_events = "[" + events_ + "]";
  const std::size_t dropped = events_dropped_;
  events_.clear();
  event_count_ = events_dropped_ = 0;
  // The views, whole, when they changed since the previous frame built (and only then).
  std::string views;
  if (server.views_revision() != views_sent_) {
    views_sent_ = server.views_revision();
    views = ", \"views\": " + views_text(server);
  }

  auto out = std::make_shared<std::string>();
  if (!kind_.binary) {
    std::string& s = *out;
    s = "{\"type\": \"frame\", \"seq\": " + std::to_string(built);
    append_clock(s, server, clock);
    s += ", \"balls\": ";
    append_balls(s, world, kind_.velocities, kind_.region.has_value(), balls_in(world, kind_));
    s += ", \"turtles\": [";
    for (std::size_t i = 0; i < server.turtle_count(); ++i) {
      if (i > 0) s += ", ";
      append_turtle_head(s, server.turtle_status(i), i < claimed.size() && claimed[i]);
      s += ", \"trail_from\": " + std::to_string(from[i]) + ", \"trail\": ";
      append_points(s, points[i]);
      s += '}';
    }
    s += "], \"walls_from\": " + std::to_string(walls_from) + ", \"walls\": ";
    append_walls(s, server, walls_from);
    s += ", \"events\": " + tail_events + ", \"events_dropped\": " + std::to_string(dropped) + views + "}";
    return out;
  }
  // Binary (docs/protocol.md, "Binary frames").
  std::string tail = "{\"events\": " + tail_events + ", \"events_dropped\": " + std::to_string(dropped) +
                     ", \"sim_events\": " + std::to_string(world.stats().events) + ", \"trails\": [";
  for (std::size_t i = 0; i < server.turtle_count(); ++i) {
    if (i > 0) tail += ", ";
    tail += "{\"from\": " + std::to_string(from[i]) + ", \"points\": ";
    append_points(tail, points[i]);
    tail += '}';
  }
  tail += "], \"walls_from\": " + std::to_string(walls_from) + ", \"walls\": ";
  append_walls(tail, server, walls_from);
  tail += views + '}';
  const std::vector<std::uint32_t> which = balls_in(world, kind_);
  const bool indexed = kind_.region.has_value();
  const std::size_t n = indexed ? which.size() : world.ball_count(), m = server.turtle_count();
  auto index = [&](std::size_t k) { return indexed ? which[k] : k; };
  std::string& s = *out;
  s.reserve(48 + n * (kind_.velocities ? 20 : 12) + m * 16 + tail.size());
  s.append("TGF1", 4);
  put<std::uint16_t>(s, 1);
  put<std::uint16_t>(s, static_cast<std::uint16_t>((clock.paused ? 1u : 0u) | (kind_.velocities ? 2u : 0u) |
                                                   (indexed ? 4u : 0u)));
  put<std::uint32_t>(s, static_cast<std::uint32_t>(built));
  put<std::uint32_t>(s, static_cast<std::uint32_t>(n));
  put<std::uint32_t>(s, static_cast<std::uint32_t>(m));
  put<std::uint32_t>(s, static_cast<std::uint32_t>(tail.size()));
  put<double>(s, server.time());
  put<double>(s, clock.wall);
  put<std::uint64_t>(s, server.step());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  if (indexed)
    for (std::uint32_t i : which) put<std::uint32_t>(s, i);
  for (std::size_t k = 0; k < n; ++k) {
    const sim::BallState b = world.ball(index(k));
    put<float>(s, b.alive ? static_cast<float>(b.pos.x) : nan);
    put<float>(s, b.alive ? static_cast<float>(b.pos.y) : nan);
  }
  if (kind_.velocities)
    for (std::size_t k = 0; k < n; ++k) {
      const sim::BallState b = world.ball(index(k));
      put<float>(s, b.alive ? static_cast<float>(b.vel.x) : 0.0f);
      put<float>(s, b.alive ? static_cast<float>(b.vel.y) : 0.0f);
    }
  std::vector<std::uint32_t> flags(m);
  for (std::size_t i = 0; i < m; ++i) {
    const turtle::WorldServer::TurtleInfo info = server.turtle_status(i);
    put<float>(s, static_cast<float>(info.state.pos.x));
    put<float>(s, static_cast<float>(info.state.pos.y));
    put<float>(s, static_cast<float>(heading_degrees(info.state)));
    flags[i] = (info.pen_down ? 1u : 0u) | (info.pen_down && info.pen_mode == turtle::PenMode::wall ? 2u : 0u) |
               (info.it ? 4u : 0u) | (info.remote ? 8u : 0u) | (i < claimed.size() && claimed[i] ? 16u : 0u) |
               (info.finished ? 32u : 0u) | (info.gone ? 64u : 0u);
  }
  for (std::uint32_t f : flags) put<std::uint32_t>(s, f);
  s += tail;
  return out;
}

}  // namespace turtlegas::server
