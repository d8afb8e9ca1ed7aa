// SPDX-License-Identifier: MIT
#include "mirror_controller.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

namespace turtlegas::turtle::detail {
namespace {

using nlohmann::json;

constexpr int max_depth = 8;  // a mirror of a mirror of ...: a loop in a file is an error, not a hang

Controller compose(const Registry& registry, const json& params, const std::string& context,
                   const std::vector<std::string>& turtle_ids, int depth) {
  auto bad = [&](const std::string& what) { return std::invalid_argument(context + ": " + what); };
  if (!params.is_object()) throw bad("the mirror controller needs params {\"of\": \"<controller>\", ...}");
  for (const auto& [key, value] : params.items())
    if (key != "of" && key != "params" && key != "axis" && key != "through" && key != "twin")
      throw bad("params." + key + ": unknown; the mirror controller takes of, params, axis, through, twin");
  if (!params.contains("of") || !params["of"].is_string())
    throw bad("params.of: name the controller to mirror, e.g. \"of\": \"wander\"");
  const std::string of = params["of"].get<std::string>();
  const json inner_params = params.value("params", json::object());
  if (!inner_params.is_object()) throw bad("params.params: must be an object, the params of " + of);
  double axis = 0.0;
  if (params.contains("axis")) {
    if (!params["axis"].is_number() || !std::isfinite(params["axis"].get<double>()))
      throw bad("params.axis: the mirror line's heading, a number of degrees (0: a vertical line)");
    axis = params["axis"].get<double>();
  }
  std::optional<sim::Vec2> through;
  if (params.contains("through")) {
    const json& p = params["through"];
    if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number())
      throw bad("params.through: a point of the mirror line, [x, y]");
    through = sim::Vec2{p[0].get<double>(), p[1].get<double>()};
  }
  if (params.contains("twin")) {
    if (!params["twin"].is_string() ||
        std::find(turtle_ids.begin(), turtle_ids.end(), params["twin"].get<std::string>()) == turtle_ids.end())
      throw bad("params.twin: the id of the turtle this one mirrors (its random stream is shared), one of this world's turtles");
  }
  Controller inner;
  json given = inner_params;  // the wrapped controller's params, with its declared defaults
  if (of == "mirror") {
    if (depth >= max_depth) throw bad("params.of: mirrors nested more than " + std::to_string(max_depth) + " deep");
    inner = compose(registry, inner_params, context + " (params.params)", turtle_ids, depth + 1);
  } else {
    const Controller* c = registry.find(of);
    if (!c) throw bad("params.of: " + registry.not_registered(of));
    inner = *c;
    // As for a turtle's own params: checked against the wrapped controller's declarations, and
    // its declared defaults filled in (Params::get<T>(key) without a fallback reads them).
    if (const ControllerInfo* info = registry.info(of)) {
      if (auto problem = check_params(of, *info, inner_params))
        throw bad("params.params" + problem->pointer + ": " + problem->reason);
      given = with_defaults(*info, inner_params);
    }
  }
  return [inner = std::move(inner), p = Params(given), axis, through](Turtle& t, const Params&) {
    Turtle m = t.mirrored(axis, through);
    inner(m, p);
  };
}

}  // namespace

Controller compose_mirror(const Registry& registry, const nlohmann::json& params, const std::string& turtle_id,
                          const std::vector<std::string>& turtle_ids) {
  return compose(registry, params, "turtle '" + turtle_id + "'", turtle_ids, 0);
}

std::string stream_owner(const std::string& controller, const nlohmann::json& params, const std::string& turtle_id) {
  if (controller == "mirror" && params.is_object() && params.contains("twin") && params["twin"].is_string())
    return params["twin"].get<std::string>();
  return turtle_id;
}

void mirror_controller(Turtle&, const Params&) {
  throw std::logic_error("the mirror controller runs only in a world: the world server composes it with params.of");
}

}  // namespace turtlegas::turtle::detail
