// SPDX-License-Identifier: MIT
// The `mirror` controller: any registered controller run as its own mirror image. The world
// server composes it when it builds a world, since it needs the registry to find params.of:
//   "controller": "mirror", "params": {"of": "wander", "params": {...}, "axis": 0, "through": [200, 0],
//                                      "twin": "left"}
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::turtle::detail {

/// What a mirror turtle runs: `params.of` (a registered controller, a mirror too if need be) with
/// `params.params`, on Turtle::mirrored(params.axis (default 0), params.through). Throws
/// std::invalid_argument, after "turtle '<id>': ", for params that are not so; `turtle_ids` are
/// the world's turtles, which params.twin must name.
Controller compose_mirror(const Registry& registry, const nlohmann::json& params, const std::string& turtle_id,
                          const std::vector<std::string>& turtle_ids);

/// The turtle whose random stream a turtle draws: its own, or a mirror's params.twin.
std::string stream_owner(const std::string& controller, const nlohmann::json& params, const std::string& turtle_id);

/// The registry entry's body: a mirror is only ever run as compose_mirror makes it.
void mirror_controller(Turtle& t, const Params& p);

}  // namespace turtlegas::turtle::detail
