// SPDX-License-Identifier: MIT
// The step clock: the start and the end of one of the memo's steps. Inside a step every body flies
// straight; at its end the field acts as a kick (kick.hpp). (Part of the Engine, whose loop serves
// the collisions inside a step: included at engine.hpp's end.)
#pragma once

// (no #include "engine.hpp": this file is the end of engine.hpp, read only from there)

namespace turtlegas::sim::detail {
namespace {

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::begin_step() {
  // Internal time zero is the start of the step; all bodies are there.
  const std::size_t n = bodies_.size();
  for (std::uint32_t i = 0; i < n; ++i) {
    if (bodies_.body[i].cell != kNone) unlink(i);
  }
  step_.dmax = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) {
    Body& b = bodies_.body[i];
    if (b.cell == kNone) continue;
    b.t = 0.0;
    step_.travel[i] = 0.0;
    if (arena_.periodic()) {
      b.x.x -= arena_.width * std::floor(b.x.x / arena_.width);
      b.x.y -= arena_.height * std::floor(b.x.y / arena_.height);
    } else if (!arena_.contains(b.x)) {
      exit(i);
      continue;
    }
    link(i, static_cast<std::uint32_t>(grid_.arena_cell_of(b.x)));
    step_.dmax = std::max(step_.dmax, path_length(b.v, dt_));
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    if (bodies_.body[i].cell == kNone) continue;
    predict(i);
    schedule(i);
  }
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::finish_step() {
  now_ = dt_;
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_.body[i].cell == kNone) continue;
    sync(i);
    // The memo: fields act as velocity kicks between steps (not on turtles).
    if (!is_turtle(i)) kick_.apply(i, bodies_.body[i].v, dt_);
  }
  // A kick changes every course, so "just collided, cannot meet again" no longer holds.
  if (kick_.changes_courses()) {
    for (std::uint32_t i = 0; i < bodies_.last.size(); ++i) bodies_.last[i] = LastPartner::none();
    bodies_.release_held();
  }
  ++step_.index;
  ++record_.stats.steps;
  ++record_.stats.events;
  turtles_.shift_times(dt_);
  schedule_.shift_times(dt_);
  bodies_.shift_held(dt_);
  if (restitution_.inelastic)
    for (double& t : restitution_.last_time) t -= dt_;
  t_base_ = static_cast<double>(step_.index) * dt_;
  shift_turtle_ends(dt_);
  schedule_.refresh_next_key(walls_, t_base_);
  now_ = 0.0;
  begin_step();
}

}  // namespace
}  // namespace turtlegas::sim::detail
