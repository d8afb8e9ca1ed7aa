// SPDX-License-Identifier: MIT
// Moving walls and visibility: keyframes in time.
// Part of engine.hpp (members of Engine), included at its end.
#pragma once

namespace turtlegas::sim::detail {
namespace {

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::aim_mover(Mover& m) {
  // From where it is now (at t_ref) towards its next pose, arriving at that pose's time.
  const auto& keys = keys_[mover_of_[m.wall]];
  if (m.next >= keys.size()) {
    m.u = {};
    m.w = {};
  } else {
    const double t_key = keys[m.next].t - t_base_;
    m.u = (keys[m.next].p1 - m.p1_ref) / (t_key - m.t_ref);
    // Exactly zero when the pose keeps its span: the translation's closed forms apply.
    m.w = keys[m.next].d == m.d_ref ? Vec2{} : (keys[m.next].d - m.d_ref) / (t_key - m.t_ref);
  }
  refresh_next_key();
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::refresh_next_key() {
  // Always from the keyframes' own times and the current base, never by shifting the old value:
  // keyframe() must find, at next_key_, the very keyframe that set it.
  next_key_ = kNever;
  for (const Mover& o : movers_) {
    const auto& k = keys_[mover_of_[o.wall]];
    if (o.next < k.size()) next_key_ = std::min(next_key_, k[o.next].t - t_base_);
  }
  for (std::size_t b = 0; b < blinkers_.size(); ++b) {
    const auto& vis = wall_defs_[blinkers_[b]].visibility;
    if (blink_next_[b] < vis.size()) next_key_ = std::min(next_key_, vis[blink_next_[b]].t - t_base_);
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::apply_visibility() {
  // Take every visibility key that is due, then rebuild the ends' layers (an end is there when any
  // of its walls is).
  bool changed = false;
  for (std::size_t b = 0; b < blinkers_.size(); ++b) {
    const std::uint32_t w = blinkers_[b];
    const auto& vis = wall_defs_[w].visibility;
    while (blink_next_[b] < vis.size() && !(vis[blink_next_[b]].t - t_base_ > now_)) {
      wall_layers_[w].mask = vis[blink_next_[b]].visible ? base_mask_[w] : 0u;
      ++blink_next_[b];
      changed = true;
    }
  }
  if (!changed) return;
  std::fill(end_layers_.begin(), end_layers_.end(), Layers{0u, 0u});
  for (std::uint32_t w = 0; w < wall_defs_.size(); ++w)
    if (mover_of_[w] == kNone)
      for (Vec2 p : {wall_defs_[w].from, wall_defs_[w].to}) add_end_layers(p, wall_layers_[w]);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::keyframe() {
  now_ = next_key_;
  ++stats_.events;
  for (Mover& m : movers_) {
    const auto& keys = keys_[mover_of_[m.wall]];
    if (m.next < keys.size() && !(keys[m.next].t - t_base_ > now_)) {
      m.p1_ref = keys[m.next].p1;  // exactly the keyframe's pose
      if (keys[m.next].d != m.d_ref) {
        m.d_ref = keys[m.next].d;
        walls_[m.wall] = make_segment(m.p1_ref, m.p1_ref + m.d_ref);  // the shape translations use
      }
      m.t_ref = now_;
      ++m.next;
    }
  }
  apply_visibility();
  for (Mover& m : movers_) aim_mover(m);
  refresh_next_key();
  for (std::uint32_t i = 0; i < body_.size(); ++i) {
    if (body_[i].cell == kNone) continue;
    sync(i);
    if (is_turtle(i) && pushed_by_[i - nb_] != kNone) {
      // The push ends with the segment of motion that made it; the turtle stands where it is.
      body_[i].v = {};
      pushed_by_[i - nb_] = kNone;
      ++body_[i].count;
    }
    // "Just collided, cannot meet again" does not survive a change of the wall's velocity.
    const LastPartner last = last_[i];
    if (!last.is_none() && (last.kind() == Partner::moving_end ||
                            (last.kind() == Partner::wall && mover_of_[last.index()] != kNone)))
      last_[i] = LastPartner::none();
    repredict(i);
  }
}

}  // namespace
}  // namespace turtlegas::sim::detail
