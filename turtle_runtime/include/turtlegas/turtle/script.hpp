// SPDX-License-Identifier: MIT
// The commands of the built-in `script` controller: one table, read by the world-file loader (which
// checks a script before the run, and takes a draw builder's commands from it) and by the
// controller that runs it.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

namespace turtlegas::turtle {

/// One script command: its name in a world file and what its number measures.
struct ScriptCommand {
  enum class Op { forward, back, left, right, wait, pendown, penup, sense, camera, arc, drive, wheels };
  /// What the command's amount is: none for pendown and penup (pendown may name a pen mode), the
  /// name of a range sensor for sense (of a camera for camera); arc, drive and wheels take several numbers (numbers()).
  enum class Amount { none, units, degrees, seconds, sensor, arc, drive, wheels };
  std::string_view name;
  Op op;
  Amount amount;
  /// Whether the command takes simulated time only (wait): a draw builder, which runs at load
  /// time, has no such command.
  bool timed_only() const { return amount == Amount::seconds; }
  /// Whether the command reads the world (sense, camera): a draw builder, which runs at load time, has none.
  bool senses() const { return amount == Amount::sensor; }
  /// Whether the command drives on an arc (arc, drive, wheels): a draw builder has none.
  constexpr bool steers() const { return amount == Amount::arc || amount == Amount::drive || amount == Amount::wheels; }
  /// How many numbers follow the name: ["arc", radius, degrees], ["drive", v, omega, seconds],
  /// ["wheels", left, right, seconds]; one for the others that take an amount.
  constexpr std::size_t numbers() const {
    switch (amount) {
      case Amount::none:
      case Amount::sensor: return 0;
      case Amount::arc: return 2;
      case Amount::drive:
      case Amount::wheels: return 3;
      default: return 1;
    }
  }
  /// An example of the command, for messages.
  constexpr std::string_view example() const {
    switch (amount) {
      case Amount::arc: return "[\"arc\", 50, 90]";
      case Amount::drive: return "[\"drive\", 20, 45, 2]";
      case Amount::wheels: return "[\"wheels\", 20, 10, 2]";
      default: return {};
    }
  }
};

/// Every script command, in the order messages list them.
inline constexpr std::array<ScriptCommand, 12> script_commands = {{
    {"forward", ScriptCommand::Op::forward, ScriptCommand::Amount::units},
    {"back", ScriptCommand::Op::back, ScriptCommand::Amount::units},
    {"left", ScriptCommand::Op::left, ScriptCommand::Amount::degrees},
    {"right", ScriptCommand::Op::right, ScriptCommand::Amount::degrees},
    {"wait", ScriptCommand::Op::wait, ScriptCommand::Amount::seconds},
    {"pendown", ScriptCommand::Op::pendown, ScriptCommand::Amount::none},
    {"penup", ScriptCommand::Op::penup, ScriptCommand::Amount::none},
    {"sense", ScriptCommand::Op::sense, ScriptCommand::Amount::sensor},
    {"camera", ScriptCommand::Op::camera, ScriptCommand::Amount::sensor},
    {"arc", ScriptCommand::Op::arc, ScriptCommand::Amount::arc},
    {"drive", ScriptCommand::Op::drive, ScriptCommand::Amount::drive},
    {"wheels", ScriptCommand::Op::wheels, ScriptCommand::Amount::wheels},
}};

/// The names of every script command, in table order ("known: ..." lists).
constexpr std::array<std::string_view, script_commands.size()> script_command_names() {
  std::array<std::string_view, script_commands.size()> names{};
  for (std::size_t k = 0; k < script_commands.size(); ++k) names[k] = script_commands[k].name;
  return names;
}

/// The command called `name`, or nullptr.
constexpr const ScriptCommand* find_script_command(std::string_view name) {
  for (const ScriptCommand& c : script_commands)
    if (c.name == name) return &c;
  return nullptr;
}

/// What the amounts measure: "units", "degrees", "seconds", ... (empty for none).
constexpr std::string_view unit_name(ScriptCommand::Amount a) {
  switch (a) {
    case ScriptCommand::Amount::units: return "units";
    case ScriptCommand::Amount::degrees: return "degrees";
    case ScriptCommand::Amount::seconds: return "seconds";
    case ScriptCommand::Amount::sensor: return "sensor";
    case ScriptCommand::Amount::arc: return "units (radius) and degrees";
    case ScriptCommand::Amount::drive: return "units/s, degrees/s and seconds";
    case ScriptCommand::Amount::wheels: return "units/s, units/s and seconds";
    case ScriptCommand::Amount::none: break;
  }
  return {};
}

}  // namespace turtlegas::turtle
