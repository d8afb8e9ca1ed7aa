// SPDX-License-Identifier: MIT
// The input log (docs/protocol.md, "The input log"): what a served world took from outside, one
// JSON object per line after a header line,
//   {"format": "turtlegas-inputs/1", "world": "NAME", "dt": 0.05}
//   {"step": 0, "turtle": "t1", "command": "forward", "amount": 100}
//   {"step": 3, "turtle": "t1", "command": "pen_down", "mode": "wall"}
//   {"step": 40, "takeover": "t2"}
//   {"step": 52, "add_wall": {"id": "w", "from": [100, 300], "to": [200, 300]}}
//   {"step": 60, "spawn": {"ball": {"id": "b9", "pos": [50, 50], "vel": [10, 0], "radius": 4}}}
//   {"step": 61, "spawn": {"turtle": {"id": "t9", "pos": [80, 80], "heading": 90}}}
//   {"step": 70, "remove": "b9"}
//   {"step": 80, "teleport": {"id": "t9", "pos": [120, 80], "heading": 180}}
//   {"step": 90, "view": {"op": "open", "view": {"id": "v1", "center": [250, 200], ...}}}
// A change made while a lockstep world waited at a boundary for a remote turtle's command (the
// host applies it there rather than make its sender wait for a boundary that needs that sender's
// command; docs/protocol.md, "Lockstep and real time") says so:
//   {"step": 52, "add_wall": {...}, "waiting": "t1", "taken": 1}
// it was made inside boundary 52's programs, while the world waited for t1's command, after t1 had
// taken `taken` commands at that boundary ("taken" is left out when 0). ReplayInput makes it there.
// View lines are display data a client sent (view_open/change/close); `serve --inputs-out` leaves
// them out (they change no physics), a recording of a served run (`serve --record`) keeps them so
// that its replay shows the client's views; ReplayInput applies them when it finds them.
// A spawn's entry is the world file's (world/entries.hpp), as the host accepted it.
// `turtlegas serve --inputs-out` writes it; ReplayInput feeds it back to a WorldServer headless
// (`turtlegas run --inputs`), which then gives the same event log bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <istream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/remote.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::formats {

inline constexpr std::string_view input_log_format = "turtlegas-inputs/1";

/// The lines, newline included.
std::string input_header_line(std::string_view world_name, double dt);
std::string input_command_line(std::uint64_t step, std::string_view turtle, const turtle::RemoteCommand& c);
std::string input_takeover_line(std::uint64_t step, std::string_view turtle);
std::string input_wall_line(std::uint64_t step, const sim::WallDef& wall);
/// kind: "ball" or "turtle"; entry: the world-file entry that was spawned.
std::string input_spawn_line(std::uint64_t step, std::string_view kind, const nlohmann::json& entry);
std::string input_remove_line(std::uint64_t step, std::string_view id);
/// A client's view change: op "open" or "change" with the whole view (view_to_json), or "close"
/// with the view's id only.
std::string input_view_line(std::uint64_t step, std::string_view op, const nlohmann::json& view);
/// `line` (a change's line from the functions here) marked as made while the world waited for
/// `turtle`'s command, after it had taken `taken` commands at that boundary.
std::string input_while_waiting(std::string line, std::string_view turtle, std::size_t taken);
/// A ball's teleport (vel) or a turtle's (heading, degrees).
std::string input_teleport_line(std::uint64_t step, std::string_view id, sim::Vec2 pos, std::optional<sim::Vec2> vel,
                                std::optional<double> heading);

/// Spawns the body of a spawn line ({"ball": {...}} or {"turtle": {...}}) into the server: the
/// host's reading of world-file entries (formats does not read world files), given to ReplayInput.
using SpawnApplier = std::function<void(turtle::WorldServer& server, const nlohmann::json& spawn)>;

/// An input log fed back at the steps it was recorded at. Throws std::invalid_argument naming
/// `file`, the line and the fix for a log that is not one, or names a turtle the world lacks.
/// During the run, next() and at_boundary() throw std::runtime_error when the run does not take
/// the inputs where they were recorded (the log belongs to another world or version).
class ReplayInput : public turtle::InputSource {
 public:
  /// `spawn` applies the log's spawn lines (a log with one and no applier is refused).
  ReplayInput(std::istream& in, const sim::WorldDef& def, std::string file, SpawnApplier spawn = {});
  void at_boundary(turtle::WorldServer& server, std::uint64_t step) override;
  /// The turtle's recorded command; first the changes recorded as made while the world waited
  /// for it at this point of the boundary.
  std::optional<turtle::RemoteCommand> next(std::uint64_t step, std::size_t turtle) override;

 private:
  struct Change {
    enum class Kind { takeover, add_wall, spawn, remove, teleport, view } kind = Kind::add_wall;
    std::uint64_t step = 0;
    std::size_t turtle = 0;  ///< takeover
    sim::WallDef wall;       ///< add_wall
    nlohmann::json body;     ///< spawn: {"ball": {...}} or {"turtle": {...}}; view: {"op", "view"}
    std::string id;          ///< remove, teleport
    sim::Vec2 pos;           ///< teleport
    std::optional<sim::Vec2> vel;
    std::optional<double> heading;
    std::optional<std::size_t> waiting;  ///< made while the world waited for this turtle's command
    std::size_t taken = 0;               ///< after it had taken this many at the boundary
  };
  void apply(turtle::WorldServer& server, Change& c) const;
  void apply_view(turtle::WorldServer& server, const nlohmann::json& v, std::uint64_t step) const;
  SpawnApplier spawn_;
  struct Command {
    std::uint64_t step = 0;
    turtle::RemoteCommand command;
  };
  std::string file_;
  std::vector<std::string> turtle_ids_;
  std::deque<Change> changes_;
  std::vector<std::deque<Command>> commands_;  // per turtle
  turtle::WorldServer* server_ = nullptr;     // the one at_boundary was last given
  std::uint64_t step_ = 0;                    // its step
  std::vector<std::size_t> taken_;            // per turtle: commands taken at that step
};

}  // namespace turtlegas::formats
