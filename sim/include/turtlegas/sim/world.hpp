// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <limits>
#include <functional>
#include <memory>
#include <stdexcept>
#include <vector>

#include "turtlegas/sim/stops.hpp"
#include "turtlegas/sim/events.hpp"
#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/sim/world_stats.hpp"

namespace turtlegas::sim {

struct Ray;
struct RayHit;
struct EngineState;

/// The momentum one collision of a ball exchanged, for observers of a gas (World::set_impulse_log):
/// wall pressure is the impulse the walls received, the virial pressure the sum of r . dp.
struct Impulse {
  double t = 0.0;  ///< seconds
  EventKind kind = EventKind::ball_ball;  ///< ball_ball, ball_wall or ball_wall_end
  std::uint32_t a = 0;  ///< the ball
  std::uint32_t b = 0;  ///< the other ball (ball_ball), or the wall's index
  /// What ball a received: its mass times its change of velocity. Ball b received -dp, a wall -dp.
  Vec2 dp;
  /// ball_ball: centre of a minus centre of b at the contact (the nearest periodic image); a wall
  /// or a wall end: centre of a minus the contact point on the wall.
  Vec2 r;
};

/// Position and velocity of one ball at the world's current time.
struct BallState {
  Vec2 pos;
  Vec2 vel;
  bool alive = true;  ///< false once the ball has exited
};

/// What a turtle is told to do. The runtime issues commands at control-step boundaries.
struct TurtleCommand {
  enum class Kind {
    stop,  ///< stand still, indefinitely
    move,  ///< drive `amount` world units along the heading (negative: backwards)
    turn,  ///< turn in place by `amount` radians (positive: clockwise, "right"); never collides
    wait,  ///< stand still for `amount` seconds
    /// drive along a circle for `amount` seconds (>= 0) at `speed` units/s along the heading
    /// (negative: backwards) while the heading turns at `rate` rad/s (positive: clockwise, as
    /// `turn`); `rate` 0 is a straight stroke, `speed` 0 a turn on the spot. The disc's path is the
    /// flight of a charged disc in a magnetic field (field_flight.hpp, w = rate), and its contacts
    /// are that flight's exact times of impact. `angle`, when finite, is the exact turn the
    /// command makes (rate * amount up to round-off): the end pose is its closed form.
    arc,
  };
  Kind kind = Kind::stop;
  double amount = 0.0;
  double speed = 0.0;  ///< arc: units/s
  double rate = 0.0;   ///< arc: rad/s, positive clockwise
  double angle = std::numeric_limits<double>::quiet_NaN();  ///< arc: radians, its exact turn (NaN: rate * amount)
};

/// A turtle's state at the world's current time.
struct TurtleState {
  Vec2 pos;
  double heading = 0.0;  ///< radians, Logo convention
  Vec2 vel;
  bool busy = false;     ///< its current command is still running
  /// Of the current (or last) command: distance driven (units, >= 0), angle turned (radians,
  /// >= 0) or time waited (s).
  double done = 0.0;
  bool touched = false;  ///< the current (or last) command was cut short by a contact
};

/// A contact involving a turtle, for its touch sensors.
struct TurtleContact {
  double t = 0.0;         ///< seconds
  std::uint32_t turtle = 0;
  EventKind kind = EventKind::turtle_wall;  ///< turtle_wall, turtle_wall_end, turtle_turtle or turtle_ball
  std::uint32_t other = 0;  ///< wall, ball or turtle index
  Vec2 normal;            ///< unit vector from the obstacle towards the turtle's centre
};

/// A run-time spawn or teleport the engine refuses (World::spawn_ball and the others): what()
/// says why; for an overlap, also which body or wall is in the way and by how much, so that a
/// caller that knows the ids can name it. Nothing has changed.
struct PlacementError : std::invalid_argument {
  enum class Obstacle { none, ball, turtle, wall };
  explicit PlacementError(const std::string& what, Obstacle o = Obstacle::none, std::size_t i = 0, double d = 0.0)
      : std::invalid_argument(what), obstacle(o), index(i), depth(d) {}
  Obstacle obstacle = Obstacle::none;
  std::size_t index = 0;  ///< the obstacle's ball, turtle or wall index
  double depth = 0.0;     ///< how far the discs (or the disc and the wall) would overlap, world units
};

/// The GAS engine: balls and walls in a uniform grid, advanced in `exact` or `step` mode.
///
/// The physics is chosen once, at construction, from the effects the scene declares: a scene
/// without gravity runs straight-line flights, one with `ball_ball` false never looks at ball
/// pairs. See docs/physics.md for the model and engine.cpp for the order of one step.
class World {
 public:
  /// Throws std::invalid_argument with the validate() message if the scene is not valid, or
  /// if a requested cell size breaks the memo's rule in step mode.
  World(const WorldDef& def, Mode mode);
  /// The same World, built from a scene it may consume: def's ball list is freed as soon as the
  /// engine has copied it, before the rest of the engine is allocated, so that a large scene and
  /// the engine built from it are never in memory together. Afterwards (also when this throws)
  /// def is valid but unspecified; keep what you still need (ball ids, say) before the call.
  World(WorldDef&& def, Mode mode);
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;
  /// An exact copy: the engine's whole state (bodies and their lazy reference times, the event
  /// queue and its pending predictions, the cell lists in their order, both clocks, the rebase
  /// and event counters, walls added since), so that the copy advanced to any t gives the events
  /// and the state the original would, bit for bit. The copy logs nowhere (set_event_log,
  /// set_impulse_log). Costs about what the engine holds (~300 bytes a ball).
  World copy() const;

  /// Whether save_state can write this engine's memory down: a gas (balls, walls, fields), not a
  /// scene with turtles, collision layers or moving walls (the engine's extras).
  bool can_save_state() const;
  /// The engine's whole memory as plain data (engine_state.hpp says what and why): a World built
  /// from the same scene and mode that takes it with restore_state goes on exactly as this one
  /// would, bit for bit. Throws std::logic_error when !can_save_state(). Costs about 100 bytes a body.
  EngineState save_state() const;
  /// Makes this World (built from the scene the state was saved from, in its mode, not advanced
  /// since) the one that saved `state`. Throws std::invalid_argument, changing nothing, for a state
  /// of another engine row, another number of bodies or walls, or links that do not hold together.
  /// The logs, the event limit and the stop poll stay this World's.
  void restore_state(const EngineState& state);

  /// Runs the physics until time t (seconds; t >= time()). Output at any t in both modes: in step
  /// mode a stop inside a step leaves the step's remaining events for the next call, so the
  /// physics does not depend on how a run is cut into calls.
  void advance_to(double t);

  /// When set, every physical event is appended to *log (nullptr stops logging).
  void set_event_log(std::vector<Event>* log);

  /// When set, every collision of a ball with a ball, a wall or a wall end appends its Impulse to
  /// *log (nullptr stops it). Costs one test per collision when unset.
  void set_impulse_log(std::vector<Impulse>* log);

  /// A bound on the events served (Stats::events, counted from construction): advance_to throws
  /// EventLimitReached when the next event would exceed it. The world is then in a consistent
  /// state at the time of the last event served, but the run cannot go on. For tests and fuzzing
  /// harnesses that must end whatever the scene does.
  void set_event_limit(std::uint64_t limit);

  /// A way to stop a long advance_to from outside (a signal, a wall-clock limit: the caller's,
  /// for sim/ has neither): `poll` is called after every `every` events served (at an event
  /// boundary, before the next event), and when it returns true advance_to throws StopRequested.
  /// The world is then as after EventLimitReached: consistent at the time of the last event
  /// served (time() says which), its state, stats and logs whole up to there, but the run cannot
  /// go on. It costs nothing per event: process() makes the one compare the event limit always
  /// did. nullptr removes it. A copy() has none.
  void set_stop_poll(std::function<bool()> poll, std::uint64_t every = 4096);

  double time() const;
  Mode mode() const;
  double dt() const;
  /// The cell side actually used (world units), and the grid size without the perimeter ring.
  double cell_size() const;
  int cells_x() const;
  int cells_y() const;

  std::size_t ball_count() const;
  BallState ball(std::size_t i) const;
  double radius(std::size_t i) const;
  double mass(std::size_t i) const;
  /// All walls: the scene's, the arena's (boundary `walls`), then those added since.
  const std::vector<WallDef>& walls() const;
  /// Adds a wall at the current time (a world built while it runs). It enters the grid and every
  /// prediction at once. Returns its index. Throws std::invalid_argument, changing nothing, if it
  /// has zero length, reaches outside a periodic arena, or overlaps a ball or a turtle.
  std::size_t add_wall(const WallDef& wall);

  // Changes to a running world (for a host, at a control boundary: call them between calls to
  // advance_to). Each is checked like a world-file entry and throws PlacementError (or
  // std::invalid_argument, std::out_of_range), changing nothing, when refused: a disc that would
  // overlap a body or a wall it collides with (per layers), a centre outside the arena (the
  // whole disc inside, with boundary walls), a bad number. Only the body concerned is predicted
  // again: every other body's events stay exactly as they were (the queue serves ties by id, and
  // ids keep their order). Not in scenes with moving walls. See docs/physics.md, "Changes to a
  // running world".
  /// Adds a ball at the current time; returns its index, ball_count() before the call (indices
  /// are never reused: a removed ball keeps its index, not alive). Refused in scenes with charged
  /// balls under a field (their flights keep per-ball species).
  std::size_t spawn_ball(const BallDef& ball);
  /// Adds a turtle standing still, no command; returns its index, turtle_count() before the
  /// call. Refused in a world built without turtles, layers or moving walls (its engine has no
  /// turtle lists: give the scene a turtle, or layers).
  std::size_t spawn_turtle(const TurtleDef& turtle);
  /// Removes ball i or turtle i now (as an exit does, without an event: the host logs it). Its
  /// index stays taken; a removed body is not alive (BallState::alive) and never met again.
  /// Throws std::out_of_range for no such body, std::invalid_argument if it is gone already.
  void remove_ball(std::size_t i);
  void remove_turtle(std::size_t i);
  /// Moves ball i to pos with velocity vel, now.
  void teleport_ball(std::size_t i, Vec2 pos, Vec2 vel);
  /// Moves turtle i to pos with heading (radians), standing still: the command it was running
  /// ends there (not touched; done what it had done).
  void teleport_turtle(std::size_t i, Vec2 pos, double heading);
  /// Whether turtle i is in the world (false once it exited, was crushed or removed).
  bool turtle_alive(std::size_t i) const;

  /// Appends to *out, in increasing order, the live balls whose centre lies in the closed
  /// rectangle [lo.x, hi.x] x [lo.y, hi.y] now (in a periodic arena: one of the centre's images
  /// does, so a rectangle may cross the seams or reach past the arena). From the grid: it looks
  /// at the cells the rectangle touches (and a ring round them, where round-off or a step's
  /// travel may have moved a ball out of its listed cell), O(cells touched + balls found).
  /// Nothing when lo > hi in either axis.
  void balls_in_rect(Vec2 lo, Vec2 hi, std::vector<std::uint32_t>& out) const;

  /// The first wall, wall end, ball or turtle the ray meets now, within its range, as its layers
  /// see them (ray_cast.hpp): walls and turtles at their pose now, moving walls included. From the
  /// grid, walked cell by cell along the ray (a periodic arena's seams crossed); it stops at the
  /// first hit proven nearest, so a ray costs about the cells it crosses. Ties go to the lower
  /// (target, index). Throws std::invalid_argument for a zero or non-finite direction, a
  /// non-finite origin, a negative or NaN range, or an infinite range in a periodic arena.
  RayHit cast_ray(const Ray& ray) const;
  /// The rays of one sensor at once: out[k] is cast_ray(ray) with ray.dir = dirs[k], bit for bit
  /// (out is resized to n). The objects within the range of the shared origin are gathered from
  /// the grid once and each ray tests those, instead of each ray walking the grid anew: a ring of 8
  /// short rays searches each cell near the turtle once rather than up to 8 times. Same errors as
  /// cast_ray; a periodic arena casts each ray alone.
  void cast_rays(const Ray& ray, const Vec2* dirs, std::size_t n, std::vector<RayHit>& out) const;

  std::size_t turtle_count() const;
  TurtleState turtle(std::size_t i) const;
  double turtle_radius(std::size_t i) const;
  /// Appends to *out, in increasing order, the turtles whose command is not running (those whose
  /// TurtleState::busy is false): one pass over compact state, for schedulers with many turtles.
  void idle_turtles(std::vector<std::uint32_t>& out) const;
  /// A cache hint, no effect on the simulation: asks for the state turtle(i) and
  /// command_turtle(i) read first. For schedulers resuming many turtles' programs in turn.
  void prefetch_turtle(std::size_t i) const;
  /// Starts a command for turtle i at the current time, replacing whatever it was doing.
  void command_turtle(std::size_t i, const TurtleCommand& command);
  /// Contacts involving turtles since the last call, in time order.
  std::vector<TurtleContact> take_turtle_contacts();

  /// Kinetic plus gravitational potential energy of the live balls; the potential of a ball is
  /// -m g.x, zero at the origin.
  double energy() const;
  const Stats& stats() const;
  /// Per ball index: the energy the zero-time rules took from it (Stats::energy_wedged and the
  /// others, summed by ball); shorter than ball_count() when the last balls gave nothing.
  const std::vector<double>& energy_taken() const;
  /// Deepest ball-ball or ball-wall overlap right now (brute force over grid neighbours).
  Overlap measure_overlap() const;
  /// Largest overlap seen at any collision so far.
  Overlap max_contact_overlap() const;

  class Impl;

 private:
  explicit World(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace turtlegas::sim
