// SPDX-License-Identifier: MIT
#include <stdexcept>
#include <string>
#include <vector>

#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::turtle {

std::vector<SensorArc> default_sensors() {
  return {{"front", -45, 45}, {"right", 45, 135}, {"back", 135, 225}, {"left", 225, 315}};
}

std::vector<SensorArc> equal_sensors(int n) {
  if (n < 1) throw std::invalid_argument("a turtle needs at least one sensor (got " + std::to_string(n) + ")");
  std::vector<SensorArc> arcs;
  arcs.reserve(static_cast<std::size_t>(n));
  const double w = 360.0 / n;
  for (int k = 0; k < n; ++k) arcs.push_back({"s" + std::to_string(k), k * w - w / 2, k * w + w / 2});
  return arcs;
}

bool Touch::fired(const std::string& sensor_name) const {
  if (!sensor_names) return false;
  for (std::size_t k = 0; k < sensor_names->size(); ++k)
    if ((*sensor_names)[k] == sensor_name) return fired(k);
  return false;
}

}  // namespace turtlegas::turtle
