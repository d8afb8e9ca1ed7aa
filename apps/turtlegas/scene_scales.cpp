// SPDX-License-Identifier: MIT
#include "scene_scales.hpp"

#include <algorithm>
#include <cmath>

#include <cstdio>

namespace turtlegas::apps {
namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

double length(sim::Vec2 v) { return std::hypot(v.x, v.y); }

}  // namespace

SceneScales predict_scales(const sim::WorldDef& def, sim::Mode mode) {
  SceneScales s;
  const double extent = std::max(def.arena.width, def.arena.height);
  const double g = length(def.effects.gravity);
  const double e = length(def.effects.electric);
  for (const sim::BallDef& b : def.balls) {
    // Energy bounds the speed a field can add while the ball crosses the arena: sqrt(2 a L).
    const double a = g + (b.mass > 0.0 ? std::abs(b.charge) * e / b.mass : 0.0);
    const double from_fields = std::sqrt(2.0 * a * extent);
    const double v = length(b.vel) + from_fields;
    s.speed_sum += 2.0 * v;
    if (!(v <= s.fastest)) {  // also takes a NaN or infinite speed
      s.fastest = v;
      s.fastest_id = b.id;
      s.by_fields = from_fields > length(b.vel);
    }
  }
  for (const sim::TurtleDef& t : def.turtles) {
    const double v = std::abs(t.speed) + std::abs(t.turn_rate) * t.radius;
    s.speed_sum += v;
    if (!(v <= s.fastest)) {
      s.fastest = v;
      s.fastest_id = t.id;
      s.by_fields = false;
    }
  }
  if (mode == sim::Mode::exact && def.effects.magnetic != 0.0) {
    for (const sim::BallDef& b : def.balls) {
      if (b.charge == 0.0 || !(b.mass > 0.0)) continue;
      const double turns = std::abs(b.charge * def.effects.magnetic / b.mass) / (2.0 * M_PI);
      s.replans_per_second += turns / 8.0;
      if (!(turns <= s.turns_per_second)) {
        s.turns_per_second = turns;
        s.gyrating_id = b.id;
      }
    }
  }
  const double per_step = 1.0 / def.dt;
  if (mode == sim::Mode::step) {
    s.steps_per_second = per_step;
    s.steps_why = "step mode at dt " + num(def.dt) + " s";
  }
  if (!def.turtles.empty()) {
    s.steps_per_second = per_step;
    s.steps_why = "control steps of dt " + num(def.dt) + " s" + (mode == sim::Mode::step ? ", and step mode's steps" : "");
  }
  return s;
}

void SceneScales::set_cell(double cell) {
  if (!(cell > 0.0)) return;
  const double crossings = speed_sum / cell;
  events_per_second = crossings + replans_per_second;
  if (!(replans_per_second <= crossings))
    events_why = "'" + gyrating_id + "' gyrates " + num(turns_per_second) +
                 " times a second in the magnetic field, and exact mode re-plans a circle every 8 turns";
  else if (!fastest_id.empty())
    events_why = "'" + fastest_id + "' may reach speed " + num(fastest) +
                 (by_fields ? " (the fields accelerate it across the arena)" : "") + ", crossing a cell of " + num(cell) +
                 " every " + num(cell / fastest) + " s";
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

std::string human_duration(double seconds) {
  if (!(seconds < 1e300)) return seconds != seconds ? "an unknown time" : "for ever";
  if (seconds < 60) return num(seconds) + " s";
  if (seconds < 3600) return num(seconds / 60) + " min";
  if (seconds < 86400 * 2) return num(seconds / 3600) + " h";
  if (seconds < 86400 * 365 * 2) return num(seconds / 86400) + " days";
  return num(seconds / (86400 * 365.25)) + " years";
}

}  // namespace turtlegas::apps
