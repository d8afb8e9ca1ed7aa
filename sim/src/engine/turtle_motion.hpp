// SPDX-License-Identifier: MIT
// Turtles' motion: the command each turtle is running, in the engine's internal time, and what a
// contact does to it. A turtle's body is in the BodyStore (id balls() + k) and the end of its
// command in its record (BodyStore::end); these functions receive both.
#pragma once

#include <cstddef>
#include <algorithm>
#include <cstdint>
#include <vector>

#include "records.hpp"
#include "turtlegas/sim/events.hpp"
#include "turtlegas/sim/control_steps.hpp"
#include "turtlegas/sim/vec2.hpp"
#include "turtlegas/sim/world.hpp"

namespace turtlegas::sim::detail {

/// A turtle's command in progress, in the engine's internal time.
struct TurtleRun {
  TurtleCommand::Kind kind = TurtleCommand::Kind::stop;
  bool coasting = false;  ///< bouncing off after a contact, until the next control step
  bool touched = false;
  double amount = 0.0;
  double t_start = 0.0;  ///< (its end is in the turtle's Record: BodyStore::end)
  double heading0 = 0.0;  ///< heading at t_start
  double omega = 0.0;     ///< signed turn rate while turning
  double speed = 0.0;
  double turn_rate = 0.0;
  double bounce = -1.0;
  /// An arc's start (Kind::arc): where it began and with what velocity, so that its end is the
  /// closed form from there rather than the sum of the round-offs of every event it passed.
  Vec2 x0;
  Vec2 v0;
  double angle = 0.0;  ///< an arc's exact turn, radians
};

/// No control boundary: a command whose end is not on one.
inline constexpr std::uint64_t kNoStep = ~std::uint64_t{0};

/// How close, in ulps of the end's external time (or of dt, whichever is larger), a command's end
/// must come to a control boundary to end on it. A duration that is a whole number of control
/// steps (forward 60 at speed 60, dt = 1/30) gives an end a few ulps off its boundary, and which
/// side of it the end falls then decided whether the program went on at that boundary or one
/// control step later (issue 28 item 8). 64 ulps is 1.4e-12 s at t = 100; a command shortened or
/// lengthened by that moves a turtle by its speed times it.
inline constexpr double kCommandSnap = 64.0 * 0x1p-52;

/// The internal time of control boundary j, internal zero being external time t_base. In step mode
/// (`steps`, with `step_index` steps done, so t_base = step_index * dt) the boundary that ends the
/// current step is the step's end, dt itself: j * dt - t_base can fall an ulp after it, and what
/// ends there would end a step late.
inline double internal_boundary(std::uint64_t j, double t_base, double dt, bool steps, std::uint64_t step_index) {
  if (steps && j == step_index + 1) return dt;
  return static_cast<double>(j) * dt - t_base;
}

/// The unit vector of a Logo heading (radians; 0 is +y, clockwise). Headings within 1e-9 degrees
/// of a multiple of 90 give the exact axis: cos(pi/2) is 6e-17, not 0, and a turtle that has
/// turned to drive along the wall it touches would otherwise "approach" it at 1e-15 units/s and
/// stop at once.
Vec2 heading_vector(double heading);

class Turtles {
 public:
  Turtles() = default;
  explicit Turtles(const std::vector<TurtleDef>& defs);

  std::size_t size() const { return run_.size(); }
  bool busy(std::size_t k) const { return busy_[k] != 0; }
  void idle(std::vector<std::uint32_t>& out) const {
    for (std::uint32_t k = 0; k < run_.size(); ++k)
      if (busy_[k] == 0) out.push_back(k);
  }
  /// The start of turtle k's command state (which may straddle two cache lines), to prefetch.
  const TurtleRun& run(std::size_t k) const { return run_[k]; }

  /// Turtle k's heading at internal time t; `end` is when its command ends.
  double heading_at(std::size_t k, double t, double end) const {
    const TurtleRun& r = run_[k];
    return r.heading0 + r.omega * (std::min(t, end) - r.t_start);
  }
  /// What turtle k's program sees (body b, brought to nothing: it is read at `now`).
  TurtleState state(std::size_t k, const Body& b, double end, double now) const;

  /// Starts command c for turtle k, whose body b has been brought to `now`: sets its velocity and
  /// `end`. Returns whether the body's course changed (false: it stood still and still does, so
  /// every prediction made with it holds).
  bool command(std::size_t k, const TurtleCommand& c, Body& b, double& end, double now);
  /// Turtle k's command, just started, ends at internal time `end` (t_base: the external time of
  /// internal zero). If that end is a control boundary to round-off (kCommandSnap) the command
  /// ends on it: returns its index, kept in end_step[k] (the caller sets `end` to its internal
  /// time, internal_boundary). kNoStep otherwise.
  std::uint64_t snap_end(std::size_t k, double end, double t_base, double dt);
  /// Turtle k's command (or its coasting after a bounce) has run its course at `now`. Returns
  /// whether the body was moving (it now stands still: its course changed).
  bool finish(std::size_t k, Body& b, double& end);
  /// Where turtle k's arc, just run to its end, ends in closed form (its start plus the circle's
  /// chord for its exact turn); its heading is set to the start's plus that turn. Call before
  /// finish(), with the body brought to the end; returns false for any other command.
  bool arc_end(std::size_t k, Vec2& pos) const;
  /// Turtle k touched something at internal time `now` (t_base: the external time of internal
  /// zero; dt: the control step): its command ends there (a dead stop, or a bounce that coasts
  /// until the next control step), and the contact waits for its touch sensors.
  void touch(std::size_t k, Body& b, double& end, double now, double t_base, double dt, EventKind kind,
             std::uint32_t other, Vec2 normal);
  /// A turtle joins at run time (world_changes.hpp): standing still, no command.
  void add(const TurtleDef& d);
  /// Turtle k is set down (a teleport, at `now`) with `heading`, standing still: the command it
  /// was running ends there, not touched, its `done` what it had done by then.
  void place(std::size_t k, double heading, Body& b, double& end, double now);
  /// Turtle k has left the arena.
  void exit(std::size_t k, Body& b, double& end);
  /// Internal time moves by -shift (a rebase, or the end of a step).
  void shift_times(double shift) {
    for (TurtleRun& r : run_) r.t_start -= shift;
  }
  std::vector<TurtleContact> take_contacts() {
    std::vector<TurtleContact> out;
    out.swap(contacts_);
    return out;
  }

  /// Per turtle: the control boundary its command (or its coast after a bounce) ends on, or
  /// kNoStep. The engine recomputes the end's internal time from it whenever internal time moves
  /// (internal_boundary), so that it stays the very double the control boundary is.
  std::vector<std::uint64_t> end_step;
  /// Per turtle: the mover (WallSchedule::movers) pushing it, or kNone.
  std::vector<std::uint32_t> pushed_by;
  /// Per turtle pushed: the turtle through which that mover pushes it (a carried turtle pushing
  /// another along), or kNone (the mover's wall itself). The contacts room sets and reads both
  /// (contacts/carried.hpp).
  std::vector<std::uint32_t> pushed_via;

 private:
  std::vector<TurtleRun> run_;
  std::vector<std::uint8_t> busy_;  ///< per turtle: a command is running (apart, so the idle scan reads 1 byte a turtle)
  std::vector<TurtleContact> contacts_;
};

/// A turtle standing still (balls under a field are never taken for one: this is for turtles).
inline bool at_rest(const Body& b) { return b.v.x == 0.0 && b.v.y == 0.0; }

}  // namespace turtlegas::sim::detail
