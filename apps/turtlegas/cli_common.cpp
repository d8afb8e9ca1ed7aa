// SPDX-License-Identifier: MIT
#include "cli_common.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <vector>

#include "turtlegas/world/world_file.hpp"

namespace turtlegas::apps {

world::Scene load(const std::string& file, const turtle::Registry& registry) {
  try {
    return world::load_scene(file, registry);
  } catch (const world::WorldFileError& e) {
    throw BadInput(e.what());
  }
}

std::unique_ptr<turtle::WorldServer> make_server(const world::Scene& scene, const turtle::Registry& registry,
                                                 const turtle::ServerOptions& options, const std::string& file) {
  try {
    return world::make_server(scene, registry, options);  // with the scene's game (scene.hpp)
  } catch (const std::invalid_argument& e) {
    throw BadInput(file + ": " + std::string(sim::to_string(options.mode)) + " mode: " + e.what());
  }
}

std::string count_summary(const sim::WorldDef& def, std::size_t balls) {
  auto plural = [](std::size_t n, const char* noun) { return std::to_string(n) + " " + noun + (n == 1 ? "" : "s"); };
  std::string s = plural(balls, "ball") + ", " + plural(def.walls.size(), "wall");
  if (def.arena.boundary == sim::Boundary::walls) s += " (+4 arena walls)";
  if (!def.turtles.empty()) s += ", " + plural(def.turtles.size(), "turtle");
  return s;
}

const char* boundary_name(sim::Boundary b) {
  switch (b) {
    case sim::Boundary::none: return "none";
    case sim::Boundary::walls: return "walls";
    case sim::Boundary::periodic: return "periodic";
  }
  return "?";
}

std::string fmt(double v) {
  std::array<char, 32> buf{};
  std::snprintf(buf.data(), buf.size(), "%.6g", v);
  return buf.data();
}

std::string controller_summary(const world::Scene& scene) {
  std::vector<std::pair<std::string, std::size_t>> uses;
  for (const turtle::TurtleProgram& p : scene.programs) {
    auto it = std::find_if(uses.begin(), uses.end(), [&](const auto& u) { return u.first == p.controller; });
    if (it == uses.end()) uses.emplace_back(p.controller, 1);
    else ++it->second;
  }
  std::string s;
  for (const auto& [name, n] : uses) s += (s.empty() ? "" : ", ") + name + (n > 1 ? " x" + std::to_string(n) : "");
  return s;
}

}  // namespace turtlegas::apps
