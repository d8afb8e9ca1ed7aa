// SPDX-License-Identifier: MIT
// The remote commands' names (remote.hpp). The remote program itself, and the scheduler's side of
// it, are in remote_program.cpp (they see the runtime's private Agent and Impl).
#include "turtlegas/turtle/remote.hpp"

#include <array>

namespace turtlegas::turtle {
namespace {

constexpr std::array<std::string_view, 13> kind_names = {"forward", "back",  "left",  "right", "wait",
                                                          "yield",   "pen_up", "pen_down", "sense", "arc",
                                                          "drive",   "wheels", "camera"};
constexpr std::array<std::string_view, 2> arc_keys = {"radius", "degrees"};
constexpr std::array<std::string_view, 3> drive_keys = {"v", "omega", "seconds"};
constexpr std::array<std::string_view, 3> wheels_keys = {"left", "right", "seconds"};

}  // namespace

std::string_view to_string(RemoteCommand::Kind kind) { return kind_names[static_cast<std::size_t>(kind)]; }

std::optional<RemoteCommand::Kind> remote_command_kind(std::string_view name) {
  for (std::size_t k = 0; k < kind_names.size(); ++k)
    if (kind_names[k] == name) return static_cast<RemoteCommand::Kind>(k);
  return std::nullopt;
}

bool takes_amount(RemoteCommand::Kind kind) {
  using K = RemoteCommand::Kind;
  return kind == K::forward || kind == K::back || kind == K::left || kind == K::right || kind == K::wait;
}

std::span<const std::string_view> steer_keys(RemoteCommand::Kind kind) {
  switch (kind) {
    case RemoteCommand::Kind::arc: return arc_keys;
    case RemoteCommand::Kind::drive: return drive_keys;
    case RemoteCommand::Kind::wheels: return wheels_keys;
    default: return {};
  }
}

}  // namespace turtlegas::turtle
