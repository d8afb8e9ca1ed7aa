// SPDX-License-Identifier: MIT
#include "cli_common.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>
#include <vector>

#include "turtlegas/world/file_error.hpp"
#include "turtlegas/world/world_file.hpp"

namespace turtlegas::apps {

world::Scene load(const std::string& file, const turtle::Registry& registry) {
  try {
    return world::load_scene(file, registry);
  } catch (const world::WorldFileError& e) {
    throw BadInput(e.what());
  }
}

world::Scene load(const std::string& file, const turtle::Registry& registry, std::string& bytes) {
  // The messages of world::load_scene, which reads the file itself.
  auto bad = [&](const std::string& what) { return BadInput(world::WorldFileError(file, "", what).what()); };
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (!std::filesystem::exists(status)) throw bad("no such file; check the path");
  if (std::filesystem::is_directory(status)) throw bad("is a directory, not a world file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw bad(std::string("cannot open: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw bad(std::string("cannot read: ") + std::strerror(errno));
  bytes = std::move(text).str();
  try {
    return world::parse_scene(bytes, file, registry);
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

bool is_recording(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(256, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::size_t at = 0;
  auto token = [&](std::string_view t) {
    while (at < head.size() && (head[at] == ' ' || head[at] == '\t' || head[at] == '\r' || head[at] == '\n')) ++at;
    if (head.compare(at, t.size(), t) != 0) return false;
    at += t.size();
    return true;
  };
  return token("{") && token("\"format\"") && token(":") && token("\"turtlegas-recording/");
}

}  // namespace turtlegas::apps
