// SPDX-License-Identifier: MIT
// The input port: turtles whose commands come from outside the process (a network client, an
// input log), applied at control boundaries so that a run stays a pure function of its inputs.
//
// A turtle whose controller is `remote` runs the runtime's own program: at every control
// boundary at which it is idle it first receives its touches and messages (reported through
// ServerOptions::remote_reports, as a C++ program's on_touch and on_message handlers would see
// them), then asks InputSource::next(step, turtle) for its next command and issues it exactly as
// a C++ program calling the Turtle API would; the command's Result is reported when the command
// ends. No command (nullopt) leaves the turtle standing still until the next boundary. Pen
// commands take no time, so several can come at one boundary before a motion command.
//
// Replaying the same commands at the same (step, turtle) gives the same run, bit for bit: the
// host records what next() returned (formats/input_log.hpp) and replays it headless.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "turtlegas/sim/vec2.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::turtle {

class WorldServer;  // world_server.hpp

/// The controller name that makes a turtle remote (`"controller": "remote"` in a world file). The
/// runtime runs it itself: it is in no Registry, and the world-file loader knows it by name.
inline constexpr std::string_view remote_controller_name = "remote";

/// One command for a remote turtle: what its C++ twin would call on its Turtle.
struct RemoteCommand {
  enum class Kind { forward, back, left, right, wait, yield, pen_up, pen_down, sense, arc, drive, wheels, camera };
  Kind kind = Kind::yield;
  double amount = 0.0;          ///< forward/back: world units; left/right: degrees; wait: seconds
  /// arc: radius (units), degrees; drive: v (units/s), omega (degrees/s), seconds; wheels: left,
  /// right (units/s), seconds. Named as steer_keys(kind) names them.
  std::array<double, 3> steer{};
  PenMode pen = PenMode::line;  ///< pen_down's mode
  /// sense: the range sensor to read (Turtle::scan); camera: the camera (Turtle::camera). Neither
  /// takes time.
  std::string sensor{};
  /// The sender's number for the command, echoed in its result; not part of the run (an input
  /// log does not record it).
  std::uint64_t tag = 0;
};

/// "forward", "back", "left", "right", "wait", "yield", "pen_up", "pen_down", "sense", "arc", "drive",
/// "wheels", "camera".
std::string_view to_string(RemoteCommand::Kind kind);
std::optional<RemoteCommand::Kind> remote_command_kind(std::string_view name);
/// Whether the command takes an amount (forward, back, left, right, wait).
bool takes_amount(RemoteCommand::Kind kind);
/// The names of RemoteCommand::steer's numbers in the protocol and in input logs: arc {"radius",
/// "degrees"}, drive {"v", "omega", "seconds"}, wheels {"left", "right", "seconds"}; empty for
/// the kinds that take none.
std::span<const std::string_view> steer_keys(RemoteCommand::Kind kind);

/// What a remote turtle's program reports, in the order its C++ twin would see it: the touches
/// and messages delivered on resuming, then the result of the command they interrupted.
struct RemoteReport {
  enum class Kind {
    touch,    ///< an interrupt (touch), before the result of the command it cut short
    message,  ///< a message from the world (the tag referee's), after the touches
    result,   ///< a command ended (command, result); pen commands and yield too
    fault,    ///< the program stopped (fault): a command the turtle may not run (a wall pen
              ///< without "builder"), as a C++ program would have thrown
  };
  Kind kind = Kind::result;
  std::size_t turtle = 0;  ///< index in the world file's turtles
  std::uint64_t step = 0;  ///< the control boundary it happened at
  double t = 0.0;          ///< seconds, the boundary's time
  RemoteCommand command;   ///< result: the command it answers (with its tag)
  Result result;           ///< result
  std::vector<Reading> readings;  ///< result of a sense or camera: every ray (pixel), as Turtle::scan (camera)
  Touch touch;             ///< touch (its sensor_names live as long as the WorldServer)
  Message message;         ///< message
  std::string fault;       ///< fault
  // The turtle as its program sees it after the report, as the Turtle API reads it.
  double heading = 0.0;   ///< degrees, Logo convention, [0, 360)
  double odometer = 0.0;  ///< units driven in all
  std::optional<sim::Vec2> position;  ///< only where the world grants it ("gps": true)
  bool it = false;        ///< the tag game's role
  bool pen_down = false;
  PenMode pen_mode = PenMode::line;
};

/// Where remote turtles' commands come from (ServerOptions::input). Called on the thread that
/// runs the WorldServer, from inside run_until.
class InputSource {
 public:
  virtual ~InputSource() = default;
  /// At the start of control boundary `step` (time step * dt), before its interrupts: the one
  /// place to change the world (WorldServer::add_wall, make_remote) so that the change is part
  /// of the run at a boundary the host chose (and can be recorded with that step).
  virtual void at_boundary(WorldServer& server, std::uint64_t step) {
    (void)server;
    (void)step;
  }
  /// The next command of remote turtle `turtle` (an index) at boundary `step`, or nullopt for
  /// none: the turtle stands still until the next boundary. May block (a lockstep host waits for
  /// its client here) and may throw, which ends the run: run_until rethrows, and the WorldServer
  /// must not be run further. It may change the world as at_boundary does (the same server, still
  /// at boundary `step`): the change lands among the boundary's programs, after those that ran
  /// before this turtle's turn, and a replay makes it at the same point (formats/input_log.hpp).
  /// A turtle spawned there first runs at the next boundary.
  virtual std::optional<RemoteCommand> next(std::uint64_t step, std::size_t turtle) = 0;
};

}  // namespace turtlegas::turtle
