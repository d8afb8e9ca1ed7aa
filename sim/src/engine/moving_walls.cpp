// SPDX-License-Identifier: MIT
#include "moving_walls.hpp"

#include <algorithm>

namespace turtlegas::sim::detail {
namespace {

/// A moving wall's keyframes as the engine keeps them (validate() has checked them). A span that
/// differs from the previous pose's by round-off only (1e-12 of its length) is taken as exactly
/// the previous one, so that a wall meant to translate runs on the translation's closed forms.
std::vector<MoverKey> mover_keys(const WallDef& wd) {
  std::vector<MoverKey> out;
  out.reserve(wd.keys.size());
  Vec2 d_prev = wd.to - wd.from;
  for (const WallKey& key : wd.keys) {
    Vec2 d = key.to - key.from;
    if (norm(d - d_prev) <= 1e-12 * norm(d_prev)) d = d_prev;
    out.push_back({key.t, key.from, d});
    d_prev = d;
  }
  return out;
}

}  // namespace

WallSchedule::WallSchedule(const Walls& walls) {
  for (std::uint32_t w = 0; w < walls.defs.size(); ++w) {
    const WallDef& wd = walls.defs[w];
    if (walls.mover_of[w] != kNone) {
      movers.push_back(Mover{w, 0, wd.from, wd.to - wd.from, 0.0, {}, {}});
      keyed.push_back(0);
      keys_.push_back(mover_keys(wd));
    }
    if (!wd.visibility.empty()) {
      blinkers_.push_back(w);
      blink_next_.push_back(0);
      base_mask_.push_back(walls.layers.empty() ? wd.layers.mask : walls.layers[w].mask);
    }
  }
}

void WallSchedule::aim(Mover& m, double t_base) {
  // From where it is now (at t_ref) towards its next pose, arriving at that pose's time.
  const auto& keys = keys_[static_cast<std::size_t>(&m - movers.data())];
  if (m.next >= keys.size()) {
    m.u = {};
    m.w = {};
  } else {
    const double t_key = keys[m.next].t - t_base;
    m.u = (keys[m.next].p1 - m.p1_ref) / (t_key - m.t_ref);
    // Exactly zero when the pose keeps its span: the translation's closed forms apply.
    m.w = keys[m.next].d == m.d_ref ? Vec2{} : (keys[m.next].d - m.d_ref) / (t_key - m.t_ref);
  }
}

void WallSchedule::aim_all(const Walls& walls, double t_base) {
  for (Mover& m : movers) aim(m, t_base);
  refresh_next_key(walls, t_base);
}

void WallSchedule::refresh_next_key(const Walls& walls, double t_base) {
  // Always from the keyframes' own times and the current base, never by shifting the old value:
  // the engine's keyframe() must find, at next_key, the very keyframe that set it.
  next_key = kNever;
  for (std::size_t m = 0; m < movers.size(); ++m) {
    const auto& k = keys_[m];
    if (movers[m].next < k.size()) next_key = std::min(next_key, k[movers[m].next].t - t_base);
  }
  for (std::size_t b = 0; b < blinkers_.size(); ++b) {
    const auto& vis = walls.defs[blinkers_[b]].visibility;
    if (blink_next_[b] < vis.size()) next_key = std::min(next_key, vis[blink_next_[b]].t - t_base);
  }
}

void WallSchedule::apply_visibility(Walls& walls, double now, double t_base) {
  // Take every visibility key that is due, then rebuild the ends' layers (an end is there when any
  // of its walls is).
  bool changed = false;
  for (std::size_t b = 0; b < blinkers_.size(); ++b) {
    const std::uint32_t w = blinkers_[b];
    const auto& vis = walls.defs[w].visibility;
    while (blink_next_[b] < vis.size() && !(vis[blink_next_[b]].t - t_base > now)) {
      walls.layers[w].mask = vis[blink_next_[b]].visible ? base_mask_[b] : 0u;
      ++blink_next_[b];
      changed = true;
    }
  }
  if (changed) walls.rebuild_end_layers();
}

void WallSchedule::take_keyframe(Walls& walls, double now, double t_base) {
  for (std::size_t k = 0; k < movers.size(); ++k) {
    Mover& m = movers[k];
    const auto& keys = keys_[k];
    if (m.next < keys.size() && !(keys[m.next].t - t_base > now)) {
      m.p1_ref = keys[m.next].p1;  // exactly the keyframe's pose
      if (keys[m.next].d != m.d_ref) {
        m.d_ref = keys[m.next].d;
        walls.segments[m.wall] = make_segment(m.p1_ref, m.p1_ref + m.d_ref);  // the shape translations use
      }
      m.t_ref = now;
      ++m.next;
      keyed[k] = 1;
    } else {
      keyed[k] = 0;
    }
  }
  apply_visibility(walls, now, t_base);
  // Only the movers that took a pose are aimed anew: aiming one that did not would recompute its
  // velocity from a shifted time base and change it by round-off, and a turtle it carries would
  // then be struck again (issue 17: a phantom touch whenever another wall reached a keyframe).
  for (std::size_t k = 0; k < movers.size(); ++k)
    if (keyed[k]) aim(movers[k], t_base);
  refresh_next_key(walls, t_base);
}

}  // namespace turtlegas::sim::detail
