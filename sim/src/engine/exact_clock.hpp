// SPDX-License-Identifier: MIT
// The exact clock: cell crossings, exits, and the rebase of internal time.
// Part of engine.hpp (members of Engine), included at its end.
#pragma once

namespace turtlegas::sim::detail {
namespace {

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::cross(std::uint32_t i) {
  ++stats_.cell_crossings;
  sync(i);
  Body& b = body_[i];
  const int dir = pending_[i].cross_dir;
  auto [ix, iy] = cell_xy(b.cell);
  ix += dir == 0 ? -1 : (dir == 1 ? 1 : 0);
  iy += dir == 2 ? -1 : (dir == 3 ? 1 : 0);
  if (ix < 1 || ix > grid_.nx() || iy < 1 || iy > grid_.ny()) {
    if (boundary_ != Boundary::periodic) {
      // The centre has left the arena. (With boundary walls this happens only if the walls were
      // missed; the body is removed rather than left to fly through the table.)
      const bool turtle = is_turtle(i);
      log(EventKind::exit, turtle ? i - nb_ : i, turtle ? 1 : 0);
      ++stats_.exits;
      remove(i);
      return;
    }
    if (ix < 1) { ix = grid_.nx(); b.x.x += width_; }
    else if (ix > grid_.nx()) { ix = 1; b.x.x -= width_; }
    if (iy < 1) { iy = grid_.ny(); b.x.y += height_; }
    else if (iy > grid_.ny()) { iy = 1; b.x.y -= height_; }
  }
  unlink(i);
  link(i, static_cast<std::uint32_t>(grid_.index(ix, iy)));
  predict_strip(i, dir, ix, iy);
  predict_crossing(i, ix, iy);
  schedule(i);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::remove(std::uint32_t i) {
  unlink(i);
  body_[i].cell = kNone;
  ++body_[i].count;  // predictions made against it are now stale
  heap_.remove(i);
  if (is_turtle(i)) {
    busy_[i - nb_] = 0;
    end_[i] = kNever;
    body_[i].v = {};
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
double Engine<Flight, kBallBall, kStep, kExtras>::rebase() {
  // Keep internal times small: absolute times would lose a bit of position per doubling of t.
  // All bodies are brought to now, which becomes internal zero. Amortised O(1) per event.
  events_since_rebase_ = 0;
  const double shift = now_;
  if (shift == 0.0) return 0.0;
  for (std::uint32_t i = 0; i < body_.size(); ++i) {
    if (body_[i].cell == kNone) continue;
    sync(i);
    body_[i].t = 0.0;
    pending_[i].t_coll -= shift;
    pending_[i].t_cross -= shift;
    if (inelastic_) last_time_[i] -= shift;
  }
  for (std::size_t k = 0; k < run_.size(); ++k) {
    run_[k].t_start -= shift;
    end_[nb_ + k] -= shift;
  }
  for (Mover& m : movers_) m.t_ref -= shift;
  t_base_ += shift;
  refresh_next_key();
  now_ = 0.0;
  heap_.shift_keys(shift);
  return shift;
}

}  // namespace
}  // namespace turtlegas::sim::detail
