// SPDX-License-Identifier: MIT
// The world server: the one owner of all bodies and of time. It runs the turtles' programs as
// coroutines between physics steps.
//
// Order of one control step, at t = k dt (AI Memo 272, "On simulating turtles"):
//   0. If ServerOptions::input is set, its at_boundary(k) runs first: the host's changes to the
//      world (add_wall, make_remote) happen here, at a boundary, so that they are part of the run.
//   1. Contacts that involved turtles during the previous step become touch interrupts.
//   1a. If the world has a game (set_game), its referee sees those contacts and may change roles
//      (Turtle::it()), queue messages for programs and log events (a `tag`), all at t.
//   2. Turtles are taken in world-file order. A turtle whose command is still running is left
//      alone. Any other turtle first receives its interrupts (its on_touch handler runs for each,
//      and each is logged as a `touch` event), then its messages (its on_message handler runs for
//      each), then its program runs until it issues its next command (or yields, or returns); the
//      command starts at once, at t. (A turtle-turtle contact ends both turtles' commands, so
//      both hear about a tag at the boundary right after it.) A turtle whose pen is in wall mode
//      lays the wall of its finished forward/back stroke when its program resumes, before its
//      handlers run: the wall is in the world, for everyone, from t on (a `wall-drawn` event).
//   3. The physics advances every body to (k+1) dt, earliest collision first. A turtle that
//      touches something stops at the contact point at the exact contact time; its command ends
//      there and the interrupt waits for the next step.
// A remote turtle (controller "remote", remote.hpp) is a program like the others whose commands
// come from ServerOptions::input, asked for in step 2 at its turn.
// Pacing (wall clock) never enters: the same world, seed and programs give the same event log.
// Threads: every WorldServer of a process runs its programs on one thread (the fibers' fault
// handling is process-wide; see src/fiber.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/world.hpp"
#include "turtlegas/turtle/colours.hpp"
#include "turtlegas/turtle/log_event.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/view.hpp"

namespace turtlegas::turtle {

/// A touch sensor: fires for contacts whose bearing lies in [from, to) degrees clockwise from the
/// heading (the arc may wrap through 0).
struct SensorArc {
  std::string name;
  double from = 0.0;
  double to = 0.0;
};

/// The default four sensors: front [-45, 45), right [45, 135), back [135, 225), left [225, 315).
std::vector<SensorArc> default_sensors();
/// n equal arcs, the first centred on the heading, named s0..s{n-1}.
std::vector<SensorArc> equal_sensors(int n);

/// A range sensor (the world file's `"senses"`): rays from the turtle's centre, each reading the
/// distance to the first wall, wall end, ball or turtle it meets within `range`, as the turtle's
/// collision layers see them (Turtle::range, Turtle::scan; docs/controllers.md, "Range sensors").
struct RangeSensor {
  std::string name;
  std::vector<double> bearings;  ///< one per ray: degrees clockwise from the heading
  double range = 100.0;          ///< world units from the turtle's centre
  /// Noise, drawn from the turtle's own seeded stream (Turtle::uniform's), so noisy runs repeat:
  double noise = 0.0;    ///< standard deviation of a Gaussian added to each hit's distance, units
  double dropout = 0.0;  ///< probability that a hit reads as nothing
  /// A line camera (the world file's `"camera"`): its rays are pixels, and each reading also
  /// gives the colour of what it hit (Colours), or `background` when nothing is within range.
  bool camera = false;
  std::string background = "#ffffff";  ///< a camera's colour for "nothing", "#rrggbb"
};

/// How a turtle's program is set up (the world file's turtle entry, beyond its body).
struct TurtleProgram {
  std::string controller = "script";
  nlohmann::json params = nlohmann::json::object();
  std::vector<SensorArc> sensors = default_sensors();
  bool pen_down = false;
  bool pen_walls = false;  ///< the pen starts in wall mode (PenMode::wall; needs builder)
  /// The turtle may lay walls with its pen (PenMode::wall). The server then moves it into a
  /// private collision category, so that it passes through its own walls (see WorldServer).
  bool builder = false;
  bool gps = false;  ///< whether the program may read its global position
  std::vector<RangeSensor> senses;  ///< range sensors, by name (none by default)
  /// Units between the wheels of Turtle::wheels; 0: twice the turtle's radius.
  double axle = 0.0;
};

/// The scene the world server runs: `def` with every builder turtle (programs[k].builder) moved
/// into a collision category of its own, a free bit from the top down, and that bit added to the
/// mask of every wall, ball and turtle that collided with the turtle's old categories. The walls a
/// builder lays leave its bit out of their mask, so it passes through them and nobody else does.
/// Throws std::invalid_argument when no bit is free.
sim::WorldDef with_builder_layers(sim::WorldDef def, const std::vector<TurtleProgram>& programs);

class InputSource;   // remote.hpp
struct RemoteReport;  // remote.hpp

struct ServerOptions {
  sim::Mode mode = sim::Mode::exact;
  std::size_t stack_bytes = 32 * 1024;  ///< each program's stack, plus a guard page
  /// Wall-clock seconds a program may run without issuing a command before the run is stopped as a
  /// busy loop. Wall clock, not simulated time: it only ever ends a run, never changes one.
  double program_budget = 2.0;
  /// Where remote turtles' commands come from, and the hook for changes at boundaries
  /// (remote.hpp). None: remote turtles stand still.
  std::shared_ptr<InputSource> input;
  /// Where remote turtles' programs report touches, messages, results and faults (remote.hpp),
  /// called from inside run_until before each InputSource::next and at the end of each step.
  std::function<void(const RemoteReport&)> remote_reports;
};

/// The busy-loop stop: a program ran past its budget without issuing a command, and was stopped
/// at its next call of the Turtle API (a query: time(), position(), touching(), ...).
struct BusyLoopError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A program that runs past its budget and calls no Turtle API for one budget more cannot be
/// stopped where it runs: it may hold the C library's locks (inside malloc), and no code of this
/// thread could run after a jump out of it. The process ends there instead: one line on stderr
/// names the turtle, its controller, the budget and the simulated time; then `last_words` runs,
/// inside a signal handler (async-signal-safe calls only: rename or unlink the outputs), and the
/// process exits with code 1. Process-wide; nullptr for none.
void set_busy_loop_last_words(void (*last_words)());

class Game;  // game.hpp

/// In a turtle's trail, the marker between two strokes (both coordinates NaN): the pen went up
/// and down again elsewhere, or the turtle was teleported with its pen down. Drawing code starts a
/// new polyline after it; the protocol writes it as `null` (docs/protocol.md, "The snapshot").
inline constexpr sim::Vec2 trail_break{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
inline bool is_trail_break(sim::Vec2 p) { return p.x != p.x; }

/// The turtle program running now on this process's simulation thread, for a crash report: a
/// fatal signal or an exit() inside a controller's code can then name the turtle and the time.
/// Plain pointers into the server's own strings, valid while that program runs; all null when
/// no program runs. Safe to read from a signal handler.
struct ProgramInFlight {
  const char* volatile turtle = nullptr;      ///< the turtle's id
  const char* volatile controller = nullptr;  ///< its controller's name
  volatile double t = 0.0;                    ///< simulated time, seconds
};
/// The program running now (see ProgramInFlight).
const ProgramInFlight& program_in_flight();

class WorldServer {
 public:
  /// programs[i] belongs to def.turtles[i]. Throws std::invalid_argument for a controller that is
  /// not registered (naming the known ones) or bad sensor arcs.
  WorldServer(const sim::WorldDef& def, std::vector<TurtleProgram> programs, const Registry& registry,
              ServerOptions options = {});
  ~WorldServer();
  WorldServer(const WorldServer&) = delete;
  WorldServer& operator=(const WorldServer&) = delete;

  /// Runs control steps until time t (seconds). Throws BusyLoopError if a program hangs, and
  /// whatever the InputSource throws; after an exception the server must not be run further.
  /// The engine's sim::EventLimitReached and sim::StopRequested (set_event_limit, set_stop_poll)
  /// come through too, the event log then whole up to the last event served.
  void run_until(double t);
  /// sim::World::set_event_limit and set_stop_poll on this server's world: bounds on a run that
  /// hold inside a control step as well as at its boundaries.
  void set_event_limit(std::uint64_t limit);
  void set_stop_poll(std::function<bool()> poll, std::uint64_t every = 4096);
  double time() const;
  /// The index of the control boundary last reached (time() == step() * dt there; run_until(t)
  /// runs the programs of a boundary at t, and the physics stops at t).
  std::uint64_t step() const;
  const sim::World& world() const;
  /// The scene as it is now: the world file's (builder turtles in their categories), with the
  /// balls and turtles spawned since appended (ids by index, for writers).
  const sim::WorldDef& scene() const;

  /// When set, events are appended to *log (nullptr stops).
  void set_event_log(std::vector<LogEvent>* log);

  /// Makes the world's game referee (step 1a above); replaces any previous game. The game starts
  /// at once (Game::start, at time()); its exceptions (std::invalid_argument for rules that do
  /// not fit the world) propagate. nullptr removes the game.
  void set_game(std::unique_ptr<Game> game);
  /// The game, or nullptr.
  const Game* game() const;

  /// An exact copy of the world at a control boundary (snapshot.cpp): the engine
  /// (sim::World::copy), the scene, the step counter and the views, so that restore() then
  /// run_until(t) gives what run_until(t) would have from the snapshot's time, bit for bit. Only
  /// for worlds without turtles and games (a turtle's program is a coroutine, whose stack cannot
  /// be copied): nullptr otherwise.
  struct Snapshot;
  std::shared_ptr<const Snapshot> snapshot() const;
  /// Puts this server back to a snapshot it took; the event log (set_event_log) stays as it is.
  void restore(const Snapshot& s);

  struct TurtleInfo {
    std::string id;
    sim::TurtleState state;
    bool pen_down = false;
    bool finished = false;  ///< the program returned (the turtle is parked)
    std::string fault;      ///< non-empty when the program failed (threw, overflowed its stack)
    std::vector<sim::Vec2> trail;  ///< pen-down path, in world units; breaks marked (is_trail_break)
    PenMode pen_mode = PenMode::line;
    bool it = false;      ///< "it" in the world's game
    bool remote = false;  ///< runs the remote program (remote.hpp)
    bool gone = false;    ///< no longer in the world: removed, crushed, or out of an open arena
  };
  std::size_t turtle_count() const;
  /// Turtle i with its whole trail (and the live tip, its position, when the pen is down).
  TurtleInfo turtle(std::size_t i) const;
  /// Turtle i without its trail (TurtleInfo::trail empty): for frames, which send trails by parts.
  TurtleInfo turtle_status(std::size_t i) const;
  /// The pen-down path's committed points (those a command's end or a pen_down added) from index
  /// `from` on; without the live tip. Empty when from >= trail_size(i). A trail is one polyline
  /// per stroke: where the pen went down again after a gap, or a pen-down turtle was teleported,
  /// a break marker (is_trail_break) separates the strokes.
  std::vector<sim::Vec2> trail_since(std::size_t i, std::size_t from) const;
  std::size_t trail_size(std::size_t i) const;
  /// The controller turtle i runs now ("remote" once make_remote made it so).
  const std::string& controller(std::size_t i) const;
  bool is_remote(std::size_t i) const;

  /// Changes for an InputSource's at_boundary (remote.hpp), at the current boundary:
  /// Adds a wall now, as sim::World::add_wall does, and logs a `wall-added` event. Throws
  /// std::invalid_argument, changing nothing, for an id that is taken or a wall the engine
  /// refuses (zero length, outside a periodic arena, overlapping a body).
  void add_wall(const sim::WallDef& wall);
  /// Detaches turtle i's program (a command it was running stops now) and gives the turtle the
  /// remote program from this boundary on; logs a `takeover` event. Touches and messages not yet
  /// delivered go to the remote program. Throws std::logic_error if the turtle is remote already
  /// or when not called from InputSource::at_boundary.
  void make_remote(std::size_t i);
  // Views (view.hpp): display data, never physics. Each change below applies at once, at time()
  // (programs and a host's messages run at control boundaries), bumps views_revision() and is
  // logged as a `view` event {"op": "open"|"change"|"close", "by": <turtle id, when a program
  // made it>, "view": {...}}; docs/viewer.md. All throw std::invalid_argument (a ViewError for a
  // bad view), changing nothing, for an id that is taken (open) or unknown (change, close) and
  // a follow that names no turtle.
  /// The world file's views, before the run starts: not logged (they are in the world file).
  void set_views(std::vector<View> views);
  /// What cameras see (Colours), before the run starts; the defaults until then.
  void set_colours(Colours colours);
  const Colours& colours() const;
  void open_view(const View& v, const std::string& by = {});
  void change_view(const View& v, const std::string& by = {});
  void close_view(const std::string& id, const std::string& by = {});
  std::optional<View> find_view(const std::string& id) const;
  /// The open views, in the order they were opened.
  const std::vector<View>& views() const;
  /// Counts the changes to views() (0 before any): frames send the views again when it moved.
  std::uint64_t views_revision() const;
  /// Where turtle i is, for view_transform.
  FollowPose follow_pose(std::size_t i) const;
  /// The index of the turtle with that id, or nullopt.
  std::optional<std::size_t> turtle_index(const std::string& id) const;

  // Bodies added, removed and moved at the current boundary (world_changes.cpp; docs/physics.md,
  // "Bodies added, removed and moved at run time"). Each throws std::invalid_argument, changing
  // nothing, for a taken or unknown id or a placement the engine refuses (the message names the
  // body in the way by its id, and by how much), and std::logic_error when not called from
  // InputSource::at_boundary. Each logs an event: `spawn`, `remove` or `teleport` (a: the id, b:
  // "ball" or "turtle").
  /// Adds a ball now; returns its index (indices are never reused).
  std::size_t spawn_ball(const sim::BallDef& ball);
  /// Adds a turtle standing still, with its program (a registered controller or "remote"), which
  /// starts at this boundary in its turn (after the turtles before it). Not a builder.
  std::size_t spawn_turtle(const sim::TurtleDef& turtle, TurtleProgram program);
  /// Removes the ball or turtle `id` now; a turtle's program is unwound (its coroutine ends) and
  /// its touches not yet delivered are dropped.
  void remove_body(const std::string& id);
  /// Moves ball `id` to pos with velocity vel.
  void teleport_ball(const std::string& id, sim::Vec2 pos, sim::Vec2 vel);
  /// Moves turtle `id` to pos facing heading_deg (degrees, Logo convention), standing still: the
  /// command it was running ends there (its result: not touched, done what it had done).
  void teleport_turtle(const std::string& id, sim::Vec2 pos, double heading_deg);
  /// Why a disc of `radius` at `pos` (default layers) could not be placed now, or nullopt: the
  /// overlaps spawn_ball and the teleports refuse (naming the body or wall in the way and by how
  /// much), measured against the present state with nothing changed, ignoring the body `self`.
  /// For a host that answers at once what the next boundary would refuse; the boundary checks again.
  std::optional<std::string> placement_problem(sim::Vec2 pos, double radius, const std::string& self = {}) const;
  /// Whether the body `id` is a ball (false: a turtle; nullopt: no such body, or removed).
  std::optional<bool> body_is_ball(const std::string& id) const;
  /// Bytes of program stack actually reserved per turtle (stack plus guard page).
  std::size_t stack_reservation() const;

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace turtlegas::turtle
