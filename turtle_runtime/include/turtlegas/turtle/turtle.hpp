// SPDX-License-Identifier: MIT
// The one header a controller program needs.
//
// A controller is a plain function that runs as the turtle's own coroutine. Each motion command
// suspends the program until the command completes in simulated time or a touch cuts it short,
// and returns what happened:
//
//   void wall_follower(turtlegas::turtle::Turtle& t, const turtlegas::turtle::Params& p) {
//     const double back_off = p.get("back_off", 5.0);
//     for (;;) {
//       auto moved = t.forward(1000);          // suspends until done or touched
//       if (moved.touched()) {
//         t.back(back_off);
//         t.left(moved.touch().front() ? 90 : 30);
//       }
//     }
//   }
//
// Angles are degrees at this interface (Logo convention: heading 0 points to +y, right turns are
// clockwise); distances are world units, times seconds.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/vec2.hpp"
#include "turtlegas/turtle/view.hpp"

namespace turtlegas::turtle {

/// A controller's parameters: the world file's `params` object (with the defaults of the
/// parameters its controller declares in the registry filled in, registry.hpp).
class Params {
 public:
  Params() = default;
  explicit Params(nlohmann::json json) : json_(std::move(json)) {}
  /// The value of `key` converted to T, or `fallback` when absent. A present value of the wrong
  /// type throws std::invalid_argument naming the key, and so does a number that an integral T
  /// cannot hold exactly (2.5, or 9e36 for an int).
  template <class T>
  T get(const std::string& key, T fallback) const {
    if (!json_.is_object() || !json_.contains(key)) return fallback;
    return convert<T>(key, json_.at(key));
  }
  double get(const std::string& key, double fallback) const { return get<double>(key, fallback); }
  /// The value of `key`, which the controller's declaration gives a default: throws
  /// std::invalid_argument when it is absent all the same (an undeclared key).
  template <class T>
  T get(const std::string& key) const {
    if (!json_.is_object() || !json_.contains(key))
      throw std::invalid_argument("params." + key + " is not given and has no declared default");
    return convert<T>(key, json_.at(key));
  }
  bool has(const std::string& key) const { return json_.is_object() && json_.contains(key); }
  const nlohmann::json& json() const { return json_; }

 private:
  template <class T>
  static T convert(const std::string& key, const nlohmann::json& v) {
    if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
      // nlohmann converts a double to an integer with a cast, which is undefined behaviour out of
      // range (laps: 9e36 made the turtle silently do nothing).
      using L = std::numeric_limits<T>;
      if (v.is_number_unsigned()) {
        if (const auto u = v.get<std::uint64_t>(); std::in_range<T>(u)) return static_cast<T>(u);
      } else if (v.is_number_integer()) {
        if (const auto i = v.get<std::int64_t>(); std::in_range<T>(i)) return static_cast<T>(i);
      } else if (v.is_number_float()) {
        const double d = v.get<double>();
        // [min, max + 1) in doubles: both ends are zero or powers of two, so exact.
        const double lo = static_cast<double>(L::min()), hi = std::ldexp(1.0, L::digits);
        if (d == std::trunc(d) && d >= lo && d < hi) return static_cast<T>(d);
      } else {
        throw std::invalid_argument("params." + key + " has the wrong type: " + v.dump());
      }
      throw std::invalid_argument("params." + key + " must be a whole number from " + std::to_string(L::min()) +
                                  " to " + std::to_string(L::max()) + ", got " + v.dump());
    } else {
      try {
        return v.get<T>();
      } catch (const nlohmann::json::exception&) {
        throw std::invalid_argument("params." + key + " has the wrong type: " + v.dump());
      }
    }
  }

  nlohmann::json json_ = nlohmann::json::object();
};

/// One touch: which sensors fired, where the contact was and what was touched.
struct Touch {
  std::uint64_t sensors = 0;  ///< bit k set: sensor k fired (the turtle's sensor order, at most 64)
  const std::vector<std::string>* sensor_names = nullptr;  ///< the turtle's sensor names; owned by the runtime
  double bearing = 0.0;       ///< degrees clockwise from the heading to the contact point, [0, 360)
  std::string what;           ///< id of the wall, ball or turtle touched
  std::string kind;           ///< "wall", "wall-end", "turtle" or "ball"
  double t = 0.0;             ///< seconds, the time of contact
  /// With the default four sensors (front, right, back, left):
  bool front() const { return fired("front"); }
  bool right() const { return fired("right"); }
  bool back() const { return fired("back"); }
  bool left() const { return fired("left"); }
  bool fired(std::size_t sensor) const { return sensor < 64 && ((sensors >> sensor) & 1u) != 0; }
  bool fired(const std::string& sensor_name) const;
  bool any() const { return sensors != 0; }
};

/// One ray of a range sensor, read now (Turtle::range, Turtle::scan).
struct Reading {
  /// World units from the turtle's centre to the first thing the ray meets; infinity when nothing
  /// is within the sensor's range.
  double distance = std::numeric_limits<double>::infinity();
  double bearing = 0.0;  ///< the ray's, degrees clockwise from the heading (as the program sees it)
  std::string what;      ///< id of the wall, ball or turtle hit; empty when nothing is
  std::string kind;      ///< "wall", "wall-end", "ball" or "turtle"; empty when nothing is hit
  /// A camera's pixel (Turtle::camera): the colour of what was hit, "#rrggbb", or the camera's
  /// background when nothing is within range; empty for a range sensor that is no camera.
  std::string colour;
  bool hit() const { return !kind.empty(); }
};

/// What a command did.
class Result {
 public:
  Result() = default;
  Result(double done, std::optional<Touch> touch)
      : done_(done), touch_(touch ? std::make_shared<const Touch>(std::move(*touch)) : nullptr) {}
  /// Distance driven (units), angle turned (degrees) or time waited (s), always >= 0.
  double done() const { return done_; }
  /// Whether a touch cut the command short.
  bool touched() const { return touch_ != nullptr; }
  /// The touch that cut it short; only when touched().
  const Touch& touch() const { return *touch_; }

 private:
  double done_ = 0.0;
  // Shared and immutable: a Result is 24 bytes, small in the controller's frame (a program's
  // frames are its stack's hot lines, fetched again at every resume), and copies cheaply.
  std::shared_ptr<const Touch> touch_;
};

/// A message to a program from the world (a game's referee, say): delivered when the program
/// next resumes, after its touches. `data` is a JSON object with at least "kind"; the tag game
/// sends {"kind": "tag", "it": true|false, "by": "<the other turtle's id>"}.
struct Message {
  nlohmann::json data = nlohmann::json::object();
  double t = 0.0;  ///< seconds, when it was sent
  std::string kind() const { return data.is_object() ? data.value("kind", std::string()) : std::string(); }
};

/// What a lowered pen does. `line` draws the turtle's path (in snapshots); `wall` lays a wall
/// along each forward/back stroke (a real wall that every other body collides with; the turtle
/// itself passes through its own walls). On an arc (arc, drive, wheels) both follow its chords:
/// each spans at most 45 degrees of the turn and lies within radius() / 20 of the arc (its
/// sagitta); an arc of more than a lap draws its circle once, then the rest. Wall mode needs a turtle the world lets build walls
/// (`"builder": true` or `"pen": "wall"` in the world file).
enum class PenMode { line, wall };

class Agent;  // the runtime's side of a turtle

/// Thrown by a command (forward, back, left, right, arc, drive, wheels, wait, yield) of a turtle that is no longer in
/// the world: crushed (docs/physics.md, "Wedged and crushed bodies"), out of an open arena, or
/// removed. The command it cuts short has ended where the turtle went; every later command throws
/// it again. A program may catch it to tidy up, then return; uncaught, it ends the program without
/// a fault (the turtle's status is `gone`, the event log already has its `crushed` or `exit`).
class TurtleGone : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The handle a controller program drives its turtle with. Valid for the program's lifetime.
class Turtle {
 public:
  explicit Turtle(Agent& agent) : agent_(&agent) {}

  Result forward(double distance);
  Result back(double distance);
  Result left(double degrees);
  Result right(double degrees);
  Result wait(double seconds);
  /// Drives along a circle of `radius` units (>= 0; 0 turns on the spot) through `degrees` of
  /// turn: positive turns right (clockwise, as right() does), negative left. It drives at speed(),
  /// or slower where that would turn faster than turn_rate() (at turn_rate() * radius, in
  /// radians), and ends at the closed form of the exact turn. done(): the distance driven along
  /// the arc (units; 0 for a turn on the spot), as the odometer counts it.
  Result arc(double radius, double degrees);
  /// Drives for `seconds` at `v` units/s along the heading (negative: backwards) while the heading
  /// turns at `omega` degrees/s (positive: clockwise): a circle of radius |v / omega| (omega in
  /// radians/s), a straight stroke when omega is 0, a turn on the spot when v is 0. When |v| >
  /// speed() or |omega| > turn_rate(), both are scaled down by one factor (the same circle,
  /// driven more slowly for the same time). done(): the distance driven along the arc (units).
  Result drive(double v, double omega_degrees_per_s, double seconds);
  /// Differential drive: the left and right wheels at `left` and `right` units/s (negative:
  /// backwards) for `seconds`, the wheels axle() apart. The turtle drives at (left + right) / 2
  /// and turns at (left - right) / axle() radians/s (clockwise when the left wheel is faster): a
  /// circle of radius axle() / 2 * |left + right| / |right - left|. A wheel faster than speed()
  /// scales both wheels down by one factor (the same circle); turn_rate() does not apply, the
  /// wheels are the limit. done(): the distance the centre drove along the arc (units).
  Result wheels(double left, double right, double seconds);
  /// Gives up the rest of this control step without a command.
  void yield();
  void pen_up();
  /// Lowers the pen. In PenMode::wall, each forward/back command from now on lays a wall from
  /// where it started to where it ended (also when a touch cut it short), at the control step at
  /// which the command returns; it is logged as a `wall-drawn` event with the id
  /// `<turtle id>-w<k>`; an arc lays one wall per chord (PenMode). A wall that would overlap a body it collides with is not laid (a
  /// `wall-refused` event says why). Throws std::logic_error for PenMode::wall when the turtle is
  /// not a builder (which stops its program with a fault naming the fix).
  void pen_down(PenMode mode = PenMode::line);
  bool pen_is_down() const;
  /// The mode of the pen (the last pen_down's; PenMode::line before any).
  PenMode pen_mode() const;

  /// The touches in contact now (sensors computed for the current heading); empty if none.
  std::vector<Touch> touching() const;
  /// Installs an interrupt handler: called for each touch, in the turtle's program, before the
  /// program resumes from the command the touch cut short. Replaces any previous handler.
  void on_touch(std::function<void(const Touch&)> handler);
  /// Installs a message handler: called for each message, in the turtle's program, when it next
  /// resumes (after the on_touch handlers, before the command that was running returns). Replaces
  /// any previous handler; messages that arrive with no handler installed are dropped.
  void on_message(std::function<void(const Message&)> handler);
  /// Whether this turtle is "it" in the world's tag game (false when the world has no game). It
  /// changes at control-step boundaries, together with the message that announces it.
  bool it() const;

  /// Range sensors (the world file's `"senses"`), read now, at the control boundary the program
  /// runs at: no simulated time passes. Each call logs a `sense` event with every ray's reading.
  /// An unknown sensor name throws std::invalid_argument naming the turtle's sensors.
  /// The sensor's first ray (a single ray's only one).
  Reading range(const std::string& sensor);
  /// Every ray of the sensor, in its order, into `out` (cleared first; its capacity is reused).
  void scan(const std::string& sensor, std::vector<Reading>& out);
  /// A line camera (a sense with `"camera"` in the world file), read now as scan() reads it: one
  /// Reading per pixel, left to right, each with the colour of what its ray hit (Reading::colour;
  /// the background when nothing). Throws std::invalid_argument for a sensor that is no camera.
  void camera(const std::string& sensor, std::vector<Reading>& out);

  /// Odometry: distance driven in all (units) and heading (degrees, Logo convention).
  double odometer() const;
  double heading() const;
  /// Global position, only where the world grants it (`"gps": true` on the turtle).
  std::optional<sim::Vec2> position() const;
  /// Simulated time, seconds.
  double time() const;
  const std::string& id() const;
  /// A per-turtle random stream seeded from the world's seed and the turtle's id: programs that
  /// draw from it are deterministic.
  double uniform();  ///< in [0, 1)
  /// A line for the run's log, tagged with the turtle's id.
  void log(const std::string& message);

  /// What a program may plan with, from the world file: the turtle's radius (units), speed
  /// (units/s) and turn rate (degrees/s), and the world's control step dt (s).
  double radius() const;
  double speed() const;
  double turn_rate() const;
  /// The distance between the wheels of wheels() (units): the world file's `"axle"`, by default
  /// twice the turtle's radius (wheels at the rim of its disc).
  double axle() const;
  double dt() const;
  /// The rules of the world's game as JSON; {} when the world has no game. The tag game gives
  /// {"kind": "tag", "no_tag_back": <seconds>}.
  nlohmann::json game_rules() const;

  /// The world's views (view.hpp): open, change and close display windows, e.g. one that follows
  /// this turtle while it is "it". Changes apply at the control boundary the program runs at, are
  /// logged as `view` events by this turtle's id, and never change the physics.
  Display display() const;

  /// This turtle seen through a mirror whose line has heading `axis_degrees` (Logo degrees; 0, the
  /// default, is a vertical line), to run a program as its own mirror image (the `mirror`
  /// controller). The handle it returns exchanges left and right, and reflects across the line
  /// the heading (heading() is 2 axis - the real heading), arcs (arc and drive turn the other
  /// way; wheels exchanges the left and right wheel), every touch (bearing b seen as 360 - b,
  /// sensors those of the reflected bearing: Result::touch(), on_touch, touching(); a range
  /// sensor's ray at bearing b reads what lies at 360 - b) and, when
  /// `through` names a point of the line, position() (without it a mirrored position() is
  /// nullopt). Distances, times, messages, the pen and uniform() are the turtle's own. Mirrored
  /// again across the same line, it is the turtle itself; across another line it throws
  /// std::invalid_argument (two reflections make a rotation, which is not a mirror).
  Turtle mirrored(double axis_degrees = 0.0, std::optional<sim::Vec2> through = std::nullopt) const;
  /// Whether this handle sees the turtle through a mirror (mirrored()).
  bool is_mirrored() const { return mirror_.on; }

 private:
  struct MirrorView {
    bool on = false;
    double axis = 0.0;  ///< the mirror line's heading, degrees
    std::optional<sim::Vec2> through;
  };
  /// A touch as the program behind a mirror sees it.
  static Touch reflected(const Touch& t, const Agent& agent);
  Result seen(Result r) const;
  Agent* agent_;
  MirrorView mirror_;
};

/// A controller program.
using Controller = std::function<void(Turtle&, const Params&)>;

}  // namespace turtlegas::turtle
