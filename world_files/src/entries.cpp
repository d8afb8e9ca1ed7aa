// SPDX-License-Identifier: MIT
#include "turtlegas/world/entries.hpp"

#include <utility>
#include <vector>

#include "reader.hpp"
#include "turtlegas/turtle/remote.hpp"
#include "turtlegas/world/file_error.hpp"

namespace turtlegas::world {
namespace {

/// The entry as the only element of `section`, read by the world file's reader; errors come back
/// with the entry's own path.
template <class Read>
void read_alone(nlohmann::json entry, const std::string& section, const std::string& file, Read read) {
  const std::string prefix = "/" + section + "/0";
  if (entry.is_object())
    for (const char* key : {"category", "collides_with"})
      if (entry.contains(key))
        throw WorldFileError(file, std::string("/") + key,
                             std::string("a spawned body is in the default collision category; leave \"") + key +
                                 "\" out (or put the body in the world file)");
  if (entry.is_object() && entry.contains("colour"))
    throw WorldFileError(file, "/colour",
                         "a spawned body takes its kind's default colour (docs/worlds.md, \"Colours\"); leave \"colour\" "
                         "out (or put the body in the world file)");
  try {
    read(nlohmann::json::array({std::move(entry)}));
  } catch (const WorldFileError& e) {
    std::string path = e.json_path;
    if (path.rfind(prefix, 0) == 0) path = path.substr(prefix.size());
    else if (path == "/" + section) path.clear();
    throw WorldFileError(file, path, e.reason);
  }
}

}  // namespace

sim::BallDef read_ball_entry(const nlohmann::json& entry, const std::string& file) {
  detail::Reader reader(file, nullptr);
  std::vector<sim::BallDef> balls;
  read_alone(entry, "balls", file, [&](const nlohmann::json& list) { reader.read_balls(list, balls); });
  return std::move(balls.at(0));
}

TurtleEntry read_turtle_entry(const nlohmann::json& entry, const std::string& file, const turtle::Registry& registry) {
  detail::Reader reader(file, &registry);
  nlohmann::json e = entry;
  if (e.is_object() && !e.contains("controller")) e["controller"] = std::string(turtle::remote_controller_name);
  std::vector<sim::TurtleDef> bodies;
  std::vector<turtle::TurtleProgram> programs;
  read_alone(std::move(e), "turtles", file,
             [&](const nlohmann::json& list) { reader.read_turtles(list, bodies, programs); });
  return {std::move(bodies.at(0)), std::move(programs.at(0))};
}

std::size_t spawn_entry(turtle::WorldServer& server, const nlohmann::json& spawn, const std::string& file,
                        const turtle::Registry& registry) {
  const bool ball = spawn.is_object() && spawn.contains("ball");
  if (!spawn.is_object() || spawn.size() != 1 || !(ball || spawn.contains("turtle")))
    throw WorldFileError(file, "", "a spawn is {\"ball\": {...}} or {\"turtle\": {...}}, a world-file entry");
  const char* key = ball ? "ball" : "turtle";
  try {
    if (ball) return server.spawn_ball(read_ball_entry(spawn.at(key), file));
    TurtleEntry t = read_turtle_entry(spawn.at(key), file, registry);
    return server.spawn_turtle(t.body, std::move(t.program));
  } catch (const WorldFileError& e) {
    throw WorldFileError(file, std::string("/") + key + e.json_path, e.reason);
  }
}

}  // namespace turtlegas::world
