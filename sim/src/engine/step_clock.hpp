// SPDX-License-Identifier: MIT
// The step clock: the start and the end of one of the memo's steps, with the field kick.
// Part of engine.hpp (members of Engine), included at its end.
#pragma once

namespace turtlegas::sim::detail {
namespace {

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::begin_step() {
  // Internal time zero is the start of the step; all bodies are there.
  const std::size_t n = body_.size();
  for (std::uint32_t i = 0; i < n; ++i) {
    if (body_[i].cell != kNone) unlink(i);
  }
  dmax_ = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) {
    Body& b = body_[i];
    if (b.cell == kNone) continue;
    b.t = 0.0;
    travel_[i] = 0.0;
    if (boundary_ == Boundary::periodic) {
      b.x.x -= width_ * std::floor(b.x.x / width_);
      b.x.y -= height_ * std::floor(b.x.y / height_);
    } else if (b.x.x < 0.0 || b.x.x > width_ || b.x.y < 0.0 || b.x.y > height_) {
      const bool turtle = is_turtle(i);
      log(EventKind::exit, turtle ? i - nb_ : i, turtle ? 1 : 0);
      ++stats_.exits;
      b.cell = kNone;
      ++b.count;
      heap_.remove(i);
      if (turtle) {
        busy_[i - nb_] = 0;
        end_[i] = kNever;
        b.v = {};
      }
      continue;
    }
    link(i, static_cast<std::uint32_t>(grid_.arena_cell_of(b.x)));
    dmax_ = std::max(dmax_, path_length(b.v, dt_));
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    if (body_[i].cell == kNone) continue;
    predict(i);
    schedule(i);
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::finish_step() {
  now_ = dt_;
  for (std::uint32_t i = 0; i < body_.size(); ++i) {
    if (body_[i].cell == kNone) continue;
    sync(i);
    // The memo: fields act as velocity kicks between steps (not on turtles).
    if (!is_turtle(i)) body_[i].v += dt_ * kick_;
  }
  // A kick changes every course, so "just collided, cannot meet again" no longer holds.
  if (kick_.x != 0.0 || kick_.y != 0.0) for (std::uint32_t i = 0; i < last_.size(); ++i) last_[i] = LastPartner::none();
  ++step_index_;
  ++stats_.steps;
  ++stats_.events;
  for (std::size_t k = 0; k < run_.size(); ++k) {
    run_[k].t_start -= dt_;
    end_[nb_ + k] -= dt_;
  }
  for (Mover& m : movers_) m.t_ref -= dt_;
  if (inelastic_)
    for (double& t : last_time_) t -= dt_;
  t_base_ = static_cast<double>(step_index_) * dt_;
  refresh_next_key();
  now_ = 0.0;
  begin_step();
}

}  // namespace
}  // namespace turtlegas::sim::detail
