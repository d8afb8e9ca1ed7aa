// SPDX-License-Identifier: MIT
#include "scene_scales.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <cstdio>

namespace turtlegas::apps {
namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

/// The id of def.balls[i], or of def.turtles[i - balls]; "" for sim::kNoBody.
std::string body_id(const sim::WorldDef& def, std::size_t i) {
  if (i < def.balls.size()) return def.balls[i].id;
  if (i != sim::kNoBody && i - def.balls.size() < def.turtles.size()) return def.turtles[i - def.balls.size()].id;
  return "";
}

}  // namespace

SceneScales predict_scales(const sim::WorldDef& def, sim::Mode mode) {
  SceneScales s;
  s.work = sim::estimate_work(def, mode, 0.0);
  s.fastest_id = body_id(def, s.work.fastest);
  s.gyrating_id = body_id(def, s.work.gyrating);
  s.steps_per_second = s.work.steps_per_s;
  if (mode == sim::Mode::step) s.steps_why = "step mode at dt " + num(def.dt) + " s";
  if (!def.turtles.empty())
    s.steps_why = "control steps of dt " + num(def.dt) + " s" + (mode == sim::Mode::step ? ", and step mode's steps" : "");
  return s;
}

void SceneScales::set_cell(double cell) {
  if (!(cell > 0.0)) return;
  work.set_cell(cell);
  events_per_second = work.events_per_s;
  switch (work.cause) {
    case sim::WorkCause::gyration:
      events_why = "'" + gyrating_id + "' gyrates " + num(work.turns_per_s) +
                   " times a second in the magnetic field, and exact mode re-plans a circle every 8 turns";
      break;
    case sim::WorkCause::speed:
    case sim::WorkCause::fields:
      events_why = "'" + fastest_id + "' may reach speed " + num(work.max_speed) +
                   (work.cause == sim::WorkCause::fields ? " (the fields accelerate it across the arena)" : "") +
                   ", crossing a cell of " + num(cell) + " every " + num(cell / work.max_speed) + " s";
      break;
    case sim::WorkCause::none: break;
  }
}

std::vector<std::string> scale_warnings(const SceneScales& scales, double seconds, const std::string& span) {
  std::vector<std::string> out;
  const double events = scales.events_per_second * seconds;
  if (!(events <= absurd_events))
    out.push_back(span + " predicts about " + num(events) + " events (" + scales.events_why + "): about " +
                  human_duration(events / nominal_events_per_second) + " at " + num(nominal_events_per_second) +
                  " events/s");
  const double steps = scales.steps_per_second * seconds;
  if (!(steps <= absurd_steps))
    out.push_back(span + " predicts about " + num(steps) + " steps (" + scales.steps_why + "): about " +
                  human_duration(steps / nominal_events_per_second) + " at " + num(nominal_events_per_second) +
                  " steps/s");
  return out;
}

std::optional<std::string> precision_warning(const sim::WorldDef& def) {
  double coordinate = std::max(std::abs(def.arena.width), std::abs(def.arena.height));
  auto reach = [&](sim::Vec2 p) { coordinate = std::max({coordinate, std::abs(p.x), std::abs(p.y)}); };
  double radius = std::numeric_limits<double>::infinity();
  std::string smallest;
  auto body = [&](sim::Vec2 pos, double r, const std::string& what) {
    reach(pos);
    if (r < radius) radius = r, smallest = what;
  };
  for (const sim::BallDef& b : def.balls) body(b.pos, b.radius, "ball '" + b.id + "'");
  for (const sim::TurtleDef& t : def.turtles) body(t.pos, t.radius, "turtle '" + t.id + "'");
  for (const sim::WallDef& w : def.walls) {
    reach(w.from), reach(w.to);
    for (const sim::WallKey& k : w.keys) reach(k.from), reach(k.to);
  }
  if (!(radius > 0.0) || !(coordinate / radius > precise_coordinate_ratio)) return std::nullopt;
  const double ratio = coordinate / radius;
  return "coordinates reach " + num(coordinate) + ", " + num(ratio) + " times the smallest radius (" + num(radius) +
         ", " + smallest + "): positions carry round-off of a few 1e-16 of the coordinates, so contacts may overlap by " +
         "about " + num(2.5e-16 * ratio) + " of a radius or more, above the 1e-9 the engine keeps up to a ratio of " +
         num(precise_coordinate_ratio) + " (docs/physics.md, \"The overlap bound\"); shift the scene towards the origin or "
         "scale it up";
}

std::string human_duration(double seconds) {
  if (!(seconds < 1e300)) return seconds != seconds ? "an unknown time" : "for ever";
  if (seconds < 60) return num(seconds) + " s";
  if (seconds < 3600) return num(seconds / 60) + " min";
  if (seconds < 86400 * 2) return num(seconds / 3600) + " h";
  if (seconds < 86400 * 365 * 2) return num(seconds / 86400) + " days";
  return num(seconds / (86400 * 365.25)) + " years";
}

}  // namespace turtlegas::apps
