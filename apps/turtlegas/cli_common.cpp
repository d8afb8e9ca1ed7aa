// SPDX-License-Identifier: MIT
#include "cli_common.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <system_error>
#include <vector>

#include "turtlegas/world/world_file.hpp"
#include "turtlegas/turtle/json_depth.hpp"

namespace turtlegas::apps {

world::Scene load(const std::string& file, const turtle::Registry& registry) {
  try {
    return world::load_scene(file, registry);
  } catch (const world::WorldFileError& e) {
    throw BadInput(e.what());
  }
}

nlohmann::ordered_json read_world_json(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw BadInput(file + ": cannot read it");
  std::stringstream text;
  text << in.rdbuf();
  if (const auto deep = turtle::json_too_deep(text.str())) throw BadInput(file + ": " + *deep + " (docs/worlds.md)");
  try {
    return nlohmann::ordered_json::parse(text.str());
  } catch (const nlohmann::json::exception& e) {
    throw BadInput(file + ": not JSON (" + std::string(e.what()) + ")");
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

namespace {

std::string range_words(const std::string& noun, const std::string& unit, const std::string& lo, const std::string& hi,
                        bool open_min, bool unbounded) {
  std::string s = "must be " + noun + (unit.empty() ? "" : " of " + unit);
  if (unbounded) return s + (open_min ? " > " : " >= ") + lo;
  return s + " from " + lo + (open_min ? " (exclusive)" : "") + " to " + hi;
}

}  // namespace

CLI::Validator real_in(double min, double max, const std::string& unit, bool min_exclusive) {
  const bool unbounded = max >= std::numeric_limits<double>::max();
  const std::string words = range_words("a number", unit, fmt(min), fmt(max), min_exclusive, unbounded);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double v = 0.0;
        const char* end = text.data() + text.size();
        const auto [ptr, ec] = std::from_chars(text.data(), end, v);
        const bool parsed = ec == std::errc() && ptr == end;
        if (parsed && std::isfinite(v) && (min_exclusive ? v > min : v >= min) && v <= max) return {};
        return words + " (got " + text + ")";
      },
      words);
}

CLI::Validator integer_in(std::int64_t min, std::int64_t max, const std::string& unit) {
  const std::string words = range_words("a whole number", unit, std::to_string(min), std::to_string(max), false,
                                        max == std::numeric_limits<std::int64_t>::max());
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        std::int64_t v = 0;
        const char* end = text.data() + text.size();
        const auto [ptr, ec] = std::from_chars(text.data(), end, v);
        if (ec == std::errc() && ptr == end && v >= min && v <= max) return {};
        return words + " (got " + text + ")";
      },
      words);
}

CLI::Option* add_stack_kib_option(CLI::App& cmd, std::size_t& kib) {
  return cmd.add_option("--stack-kib", kib, "Each turtle program's stack, KiB (a guard page is added)")
      ->capture_default_str()
      ->check(integer_in(16, 1024 * 1024, "KiB"));
}

CLI::Option* add_program_budget_option(CLI::App& cmd, double& seconds, const std::string& what_stops) {
  return cmd
      .add_option("--program-budget", seconds,
                  "Wall-clock seconds a turtle program may run without issuing a command before " + what_stops)
      ->capture_default_str()
      ->check(real_in(0, 1e6, "seconds", true));
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
