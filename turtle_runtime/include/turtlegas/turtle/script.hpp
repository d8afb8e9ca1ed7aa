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
  enum class Op { forward, back, left, right, wait, pendown, penup, sense };
  /// What the command's amount is: none for pendown and penup (pendown may name a pen mode), the
  /// name of a range sensor for sense.
  enum class Amount { none, units, degrees, seconds, sensor };
  std::string_view name;
  Op op;
  Amount amount;
  /// Whether the command takes simulated time only (wait): a draw builder, which runs at load
  /// time, has no such command.
  bool timed_only() const { return amount == Amount::seconds; }
  /// Whether the command reads the world (sense): a draw builder, which runs at load time, has none.
  bool senses() const { return amount == Amount::sensor; }
};

/// Every script command, in the order messages list them.
inline constexpr std::array<ScriptCommand, 8> script_commands = {{
    {"forward", ScriptCommand::Op::forward, ScriptCommand::Amount::units},
    {"back", ScriptCommand::Op::back, ScriptCommand::Amount::units},
    {"left", ScriptCommand::Op::left, ScriptCommand::Amount::degrees},
    {"right", ScriptCommand::Op::right, ScriptCommand::Amount::degrees},
    {"wait", ScriptCommand::Op::wait, ScriptCommand::Amount::seconds},
    {"pendown", ScriptCommand::Op::pendown, ScriptCommand::Amount::none},
    {"penup", ScriptCommand::Op::penup, ScriptCommand::Amount::none},
    {"sense", ScriptCommand::Op::sense, ScriptCommand::Amount::sensor},
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

/// "units", "degrees" or "seconds" (empty for none).
constexpr std::string_view unit_name(ScriptCommand::Amount a) {
  switch (a) {
    case ScriptCommand::Amount::units: return "units";
    case ScriptCommand::Amount::degrees: return "degrees";
    case ScriptCommand::Amount::seconds: return "seconds";
    case ScriptCommand::Amount::sensor: return "sensor";
    case ScriptCommand::Amount::none: break;
  }
  return {};
}

}  // namespace turtlegas::turtle
