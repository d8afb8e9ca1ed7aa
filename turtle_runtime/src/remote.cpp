// SPDX-License-Identifier: MIT
// The remote commands' names (remote.hpp). The remote program itself, and the scheduler's side of
// it, are in remote_program.cpp (they see the runtime's private Agent and Impl).
#include "turtlegas/turtle/remote.hpp"

#include <array>

namespace turtlegas::turtle {
namespace {

constexpr std::array<std::string_view, 9> kind_names = {"forward", "back",  "left",     "right", "wait",
                                                         "yield",   "pen_up", "pen_down", "sense"};

}  // namespace

std::string_view to_string(RemoteCommand::Kind kind) { return kind_names[static_cast<std::size_t>(kind)]; }

std::optional<RemoteCommand::Kind> remote_command_kind(std::string_view name) {
  for (std::size_t k = 0; k < kind_names.size(); ++k)
    if (kind_names[k] == name) return static_cast<RemoteCommand::Kind>(k);
  return std::nullopt;
}

bool takes_amount(RemoteCommand::Kind kind) {
  return kind != RemoteCommand::Kind::yield && kind != RemoteCommand::Kind::pen_up &&
         kind != RemoteCommand::Kind::pen_down && kind != RemoteCommand::Kind::sense;
}

}  // namespace turtlegas::turtle
