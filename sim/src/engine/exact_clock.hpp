// SPDX-License-Identifier: MIT
// The exact clock: cell crossings, exits from an open arena, and the rebase that keeps internal
// times small. (Part of the Engine, whose loop serves these events: included at engine.hpp's end.)
#pragma once

// (no #include "engine.hpp": this file is the end of engine.hpp, read only from there)

namespace turtlegas::sim::detail {
namespace {

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
inline void Engine<F, kBallBall, kStep, kExtras>::cross(std::uint32_t i) {
  const int dir = bodies_.pending[i].cross_dir;
  if constexpr (kSlides) {
    if (dir == kSlideEnd) [[unlikely]] {
      // The foot of a sliding ball has reached an end of its wall: it flies under the field again
      // (docs/physics.md, "The sliding flight"), from the end, with its velocity along the wall.
      sync(i);
      motion_.flight().end_slide(i);
      parts().changed(i);
      repredict(i);
      return;
    }
  }
  if constexpr (F::kBoundedHorizon) {
    if (dir == kReplan) {
      // The prediction's horizon, not a crossing: the body stays in its cell and looks again.
      sync(i);
      repredict(i);
      return;
    }
  }
  ++record_.stats.cell_crossings;
  sync(i);
  Body& b = bodies_.body[i];
  auto [ix, iy] = cell_xy(b.cell);
  ix += dir == 0 ? -1 : (dir == 1 ? 1 : 0);
  iy += dir == 2 ? -1 : (dir == 3 ? 1 : 0);
  if (ix < 1 || ix > grid_.nx() || iy < 1 || iy > grid_.ny()) {
    if (!arena_.periodic()) {
      // The centre has left the arena. (With boundary walls this happens only if the walls were
      // missed; the body is removed rather than left to fly through the table.)
      unlink(i);
      exit(i);
      return;
    }
    if (ix < 1) { ix = grid_.nx(); b.x.x += arena_.width; }
    else if (ix > grid_.nx()) { ix = 1; b.x.x -= arena_.width; }
    if (iy < 1) { iy = grid_.ny(); b.x.y += arena_.height; }
    else if (iy > grid_.ny()) { iy = 1; b.x.y -= arena_.height; }
  }
  unlink(i);
  link(i, static_cast<std::uint32_t>(grid_.index(ix, iy)));
  if constexpr (F::kBoundedHorizon) {
    if (motion_.flight().closed_forms()) {
      // The old prediction is good beyond this crossing (closed forms, no horizon): the new strip.
      look_at_strip<kBallBall>(look(), grid_, i, b, dir, ix, iy, bodies_.pending[i]);
      predict_crossing(i, ix, iy);
    } else {
      // The old prediction looked only as far as this crossing: predict afresh from the new cell.
      predict_crossing(i, ix, iy);
      predict(i, ix, iy);
    }
  } else {
    look_at_strip<kBallBall>(look(), grid_, i, b, dir, ix, iy, bodies_.pending[i]);
    predict_crossing(i, ix, iy);
  }
  schedule(i);
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::exit(std::uint32_t i) {
  // (Unlinked already.) The log names a turtle by its own index, with b = 1 (events.hpp).
  const bool turtle = is_turtle(i);
  const std::uint32_t nb = bodies_.balls();
  record_.note(t_base_ + now_, EventKind::exit, turtle ? i - nb : i, turtle ? 1 : 0);
  ++record_.stats.exits;
  retire(i);
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
double Engine<F, kBallBall, kStep, kExtras>::rebase() {
  // Keep internal times small: absolute times would lose a bit of position per doubling of t.
  // All bodies are brought to now, which becomes internal zero. Amortised O(1) per event.
  events_since_rebase_ = 0;
  const double shift = now_;
  if (shift == 0.0) return 0.0;
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_.body[i].cell == kNone) continue;
    sync(i);
    bodies_.body[i].t = 0.0;
    bodies_.pending[i].t_coll -= shift;
    bodies_.pending[i].t_cross -= shift;
    if (restitution_.inelastic) restitution_.last_time[i] -= shift;
  }
  turtles_.shift_times(shift);
  schedule_.shift_times(shift);
  bodies_.shift_held(shift);
  t_base_ += shift;
  shift_turtle_ends(shift);
  schedule_.refresh_next_key(walls_, t_base_);
  now_ = 0.0;
  heap_.shift_keys(shift);
  return shift;
}

}  // namespace
}  // namespace turtlegas::sim::detail
