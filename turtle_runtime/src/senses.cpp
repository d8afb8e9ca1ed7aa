// SPDX-License-Identifier: MIT
// Range sensors (the world file's `"senses"`): each ray cast from the turtle's centre through the
// engine's grid (sim::World::cast_ray), as the turtle's layers see the world, at the control
// boundary the program runs at; every reading is logged as a `sense` event. A camera is a range
// sensor whose readings also carry the colour of what each ray hit (WorldServer::colours).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "agent.hpp"
#include "server_impl.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/sim/format.hpp"
#include "turtlegas/sim/ray_cast.hpp"
#include "turtlegas/sim/suggest.hpp"

namespace turtlegas::turtle {
namespace {

/// The contact kind whose partner index a ray's target index is (event_names.hpp names it).
sim::EventKind contact_kind(sim::RayTarget t) {
  switch (t) {
    case sim::RayTarget::wall: return sim::EventKind::turtle_wall;
    case sim::RayTarget::wall_end: return sim::EventKind::turtle_wall_end;
    case sim::RayTarget::ball: return sim::EventKind::turtle_ball;
    default: return sim::EventKind::turtle_turtle;
  }
}

}  // namespace

void Agent::sense(const std::string& name, bool mirrored, std::vector<Reading>& out, bool camera_only) {
  const RangeSensor* sensor = nullptr;
  for (const RangeSensor& s : program.senses)
    if (s.name == name) sensor = &s;
  if (!sensor) {
    std::vector<std::string> known;
    for (const RangeSensor& s : program.senses) known.push_back(s.name);
    throw std::invalid_argument("turtle '" + id + "' has no range sensor \"" + name + "\"" +
                                (known.empty() ? std::string("; declare it under the turtle's \"senses\" in the world file")
                                               : "; its senses: " + sim::join_names(known)));
  }
  if (camera_only && !sensor->camera) {
    std::vector<std::string> cameras;
    for (const RangeSensor& s : program.senses)
      if (s.camera) cameras.push_back(s.name);
    throw std::invalid_argument("turtle '" + id + "': sensor \"" + name + "\" is a range sensor, not a camera" +
                                (cameras.empty() ? std::string("; declare one as {\"name\": \"cam\", \"camera\": {\"pixels\": 64, "
                                                               "\"fov\": 60, \"range\": 200}} under the turtle's \"senses\"")
                                                 : "; its cameras: " + sim::join_names(cameras)) +
                                " (Turtle::scan reads any sensor's distances)");
  }
  const sim::World& w = server->world;
  const sim::TurtleState st = w.turtle(index);
  sim::Ray ray;
  ray.origin = st.pos;
  ray.range = sensor->range;
  ray.layers = server->def.turtles[index].layers;
  ray.self = static_cast<std::uint32_t>(index);
  out.clear();
  out.reserve(sensor->bearings.size());
  // The rays at once (World::cast_rays: cast_ray's answers, the grid near the turtle read once).
  thread_local std::vector<sim::Vec2> dirs;
  thread_local std::vector<sim::RayHit> cast;
  dirs.clear();
  for (const double b : sensor->bearings) {
    // Behind a mirror the program's bearing b looks along 360 - b (Turtle::mirrored).
    const double heading = st.heading + sim::to_radians(mirrored ? -b : b);
    dirs.push_back({std::sin(heading), std::cos(heading)});  // Logo: 0 is +y, clockwise
  }
  w.cast_rays(ray, dirs.data(), dirs.size(), cast);
  // The sense event's text only when there is a log to take it (a bench, a batch run without one).
  const bool logged = server->log != nullptr;
  std::string ranges = "[", hits = "[", colours = "[";
  for (std::size_t k = 0; k < sensor->bearings.size(); ++k) {
    const double b = sensor->bearings[k];
    sim::RayHit hit = cast[k];
    if (hit.hit() && (sensor->noise > 0.0 || sensor->dropout > 0.0)) {
      // From the program's own stream, only for noisy sensors: noiseless runs draw nothing.
      auto uniform = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
      if (sensor->dropout > 0.0 && uniform() < sensor->dropout) {
        hit = {};
      } else if (sensor->noise > 0.0) {
        // Box-Muller: 1 - u is in (0, 1], so the logarithm is finite.
        const double g = std::sqrt(-2.0 * std::log(1.0 - uniform())) * std::cos(2.0 * M_PI * uniform());
        hit.distance = std::max(0.0, hit.distance + sensor->noise * g);
        if (hit.distance > sensor->range) hit = {};
      }
    }
    Reading r;
    r.bearing = b;
    if (logged && k > 0) {
      ranges += ", ";
      hits += ", ";
      colours += ", ";
    }
    if (hit.hit()) {
      r.distance = hit.distance;
      r.what = std::string(server->other_id(contact_kind(hit.target), hit.index));
      r.kind = hit.target == sim::RayTarget::wall       ? "wall"
               : hit.target == sim::RayTarget::wall_end ? "wall-end"
               : hit.target == sim::RayTarget::ball     ? "ball"
                                                        : "turtle";
      if (logged) {
        ranges += sim::format_number(hit.distance);
        hits += nlohmann::json(r.what).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
      }
      if (sensor->camera) r.colour = server->colours.of(r.kind, r.what);
    } else {
      if (logged) {
        ranges += "null";
        hits += "null";
      }
      if (sensor->camera) r.colour = sensor->background;
    }
    if (logged && sensor->camera) colours += nlohmann::json(r.colour).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    out.push_back(std::move(r));
  }
  if (!logged) return;
  LogEvent e;
  e.t = w.time();
  e.kind = "sense";
  e.a = id;
  e.extra = "\"sensor\": " + nlohmann::json(name).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) +
            ", \"range\": " + ranges + "], \"hit\": " + hits + "]" +
            (sensor->camera ? ", \"colour\": " + colours + "]" : std::string());
  server->emit(std::move(e));
}

Reading Turtle::range(const std::string& sensor) {
  std::vector<Reading> out;
  scan(sensor, out);
  return out.front();
}

void Turtle::scan(const std::string& sensor, std::vector<Reading>& out) {
  detail::Fiber::safe_point();
  agent_->sense(sensor, mirror_.on, out);
}

void Turtle::camera(const std::string& sensor, std::vector<Reading>& out) {
  detail::Fiber::safe_point();
  agent_->sense(sensor, mirror_.on, out, true);
}

}  // namespace turtlegas::turtle
