// SPDX-License-Identifier: MIT
// The input log (docs/protocol.md, "The input log"): what a served world took from outside, one
// JSON object per line after a header line,
//   {"format": "turtlegas-inputs/1", "world": "NAME", "dt": 0.05}
//   {"step": 0, "turtle": "t1", "command": "forward", "amount": 100}
//   {"step": 3, "turtle": "t1", "command": "pen_down", "mode": "wall"}
//   {"step": 40, "takeover": "t2"}
//   {"step": 52, "add_wall": {"id": "w", "from": [100, 300], "to": [200, 300]}}
// `turtlegas serve --inputs-out` writes it; ReplayInput feeds it back to a WorldServer headless
// (`turtlegas run --inputs`), which then gives the same event log bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <istream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

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

/// An input log fed back at the steps it was recorded at. Throws std::invalid_argument naming
/// `file`, the line and the fix for a log that is not one, or names a turtle the world lacks.
/// During the run, next() and at_boundary() throw std::runtime_error when the run does not take
/// the inputs where they were recorded (the log belongs to another world or version).
class ReplayInput : public turtle::InputSource {
 public:
  ReplayInput(std::istream& in, const sim::WorldDef& def, std::string file);
  void at_boundary(turtle::WorldServer& server, std::uint64_t step) override;
  std::optional<turtle::RemoteCommand> next(std::uint64_t step, std::size_t turtle) override;

 private:
  struct Change {
    std::uint64_t step = 0;
    std::optional<std::size_t> takeover;
    sim::WallDef wall;
  };
  struct Command {
    std::uint64_t step = 0;
    turtle::RemoteCommand command;
  };
  std::string file_;
  std::vector<std::string> turtle_ids_;
  std::deque<Change> changes_;
  std::vector<std::deque<Command>> commands_;  // per turtle
};

}  // namespace turtlegas::formats
