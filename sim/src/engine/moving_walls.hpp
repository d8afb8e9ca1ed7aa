// SPDX-License-Identifier: MIT
// Moving walls and walls that come and go: the scene's schedule of wall changes. Between two
// keyframes each end of a moving wall moves in a straight line at constant velocity; a visibility
// key switches a wall's mask off or back on. Either is a keyframe, at which every body predicts
// again (the engine's keyframe()).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "records.hpp"
#include "turtlegas/sim/toi.hpp"
#include "walls.hpp"

namespace turtlegas::sim::detail {

/// A moving wall's pose at a keyframe: its first end and the vector to its second.
struct MoverKey {
  double t = 0.0;  ///< scene time, seconds
  Vec2 p1;
  Vec2 d;
};

/// A wall moving through keyframes: between two poses each end moves in a straight line at
/// constant velocity. When both ends move alike (w == 0) the wall translates at u, and in its own
/// frame every flight is the usual one with v - u (closed forms); otherwise it turns and stretches
/// as well, and contacts with its interior are found by bracketed root finding.
struct Mover {
  std::uint32_t wall = 0;
  std::size_t next = 0;  ///< the keyframe it is heading for (keys.size(): it has stopped)
  Vec2 p1_ref;           ///< its first end at internal time t_ref
  Vec2 d_ref;            ///< second end minus first, at t_ref
  double t_ref = 0.0;
  Vec2 u{};              ///< the first end's velocity, units/s
  Vec2 w{};              ///< d(d_ref)/dt: the second end's velocity minus the first's
  bool rigid() const { return w.x == 0.0 && w.y == 0.0; }

  Vec2 p1_at(double t) const { return p1_ref + (t - t_ref) * u; }
  Vec2 d_at(double t) const { return d_ref + (t - t_ref) * w; }
  /// One end at internal time t (the second through the translation's fixed shape `s`, the
  /// wall's segment, when it does not turn or stretch), and that end's velocity.
  Vec2 end_at(const Segment& s, bool second, double t) const {
    const Vec2 p1 = p1_at(t);
    if (!second) return p1;
    return rigid() ? p1 + s.len * s.u : p1 + d_at(t);
  }
  Vec2 end_velocity(bool second) const { return second ? u + w : u; }
  /// The wall as a segment at internal time t (`s`: its segment as of the last keyframe).
  Segment segment_at(const Segment& s, double t) const {
    if (rigid()) {
      Segment out = s;
      out.p1 = p1_at(t);
      return out;
    }
    const Vec2 p1 = p1_at(t);
    return make_segment(p1, p1 + d_at(t));
  }
};

class WallSchedule {
 public:
  WallSchedule() = default;
  /// The moving walls of `walls` (Walls::mover_of numbers them) and those with visibility keys.
  explicit WallSchedule(const Walls& walls);

  std::vector<Mover> movers;
  /// Per mover: whether the last take_keyframe() gave it a new pose (its course changed there).
  std::vector<std::uint8_t> keyed;
  double next_key = kNever;  ///< internal time of the next keyframe of any moving or blinking wall

  /// Takes the visibility keys due at internal time `now` (and at construction, those at 0).
  void apply_visibility(Walls& walls, double now, double t_base);
  /// Aims every mover from where it is towards its next pose, then finds the next keyframe.
  void aim_all(const Walls& walls, double t_base);
  /// The keyframe at internal time `now` (== next_key): movers due take their poses exactly
  /// (their walls' segments follow), visibility keys due apply, and everything is aimed anew.
  void take_keyframe(Walls& walls, double now, double t_base);
  /// Recomputes next_key from the keyframes' own times and the current base (after a rebase).
  void refresh_next_key(const Walls& walls, double t_base);
  /// Internal time moves by -shift (a rebase, or the end of a step).
  void shift_times(double shift) {
    for (Mover& m : movers) m.t_ref -= shift;
  }

 private:
  void aim(Mover& m, double t_base);
  std::vector<std::vector<MoverKey>> keys_;  ///< by mover
  std::vector<std::uint32_t> blinkers_;      ///< walls whose visibility changes in time
  std::vector<std::size_t> blink_next_;      ///< per blinker: its next visibility key
  std::vector<std::uint32_t> base_mask_;     ///< per blinker: its mask while it is there
};

}  // namespace turtlegas::sim::detail
