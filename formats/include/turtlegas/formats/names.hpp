// SPDX-License-Identifier: MIT
// Ids by index for the writers: the `Names` of turtle/event_names.hpp (ball(i), wall(i), turtle(i)).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::formats {

/// Ball ids packed into one buffer (a std::string each would cost 32 bytes a ball, more than
/// the engine's whole per-ball budget allows beside it).
class IdTable {
 public:
  void reserve(std::size_t ids, std::size_t chars) {
    end_.reserve(ids);
    chars_.reserve(chars);
  }
  void push_back(std::string_view id) {
    chars_.append(id);
    end_.push_back(chars_.size());
  }
  std::string_view operator[](std::size_t i) const {
    const std::size_t begin = i == 0 ? 0 : end_[i - 1];
    return std::string_view(chars_).substr(begin, end_[i] - begin);
  }
  std::size_t size() const { return end_.size(); }

 private:
  std::string chars_;
  std::vector<std::size_t> end_;
};

/// The ball ids of a scene, packed (before the World takes the balls over).
inline IdTable ball_ids(const sim::WorldDef& def) {
  IdTable ids;
  std::size_t chars = 0;
  for (const sim::BallDef& b : def.balls) chars += b.id.size();
  ids.reserve(def.balls.size(), chars);
  for (const sim::BallDef& b : def.balls) ids.push_back(b.id);
  return ids;
}

/// A run's ids: balls from an IdTable (the scene may have given its balls to the World), turtles
/// from the scene, walls from the World (which holds the walls laid while it runs too).
struct RunNames {
  const IdTable& balls;
  const sim::WorldDef& def;
  const sim::World& world;
  std::string_view ball(std::size_t i) const { return balls[i]; }
  std::string_view wall(std::size_t i) const { return world.walls()[i].id; }
  std::string_view turtle(std::size_t i) const { return def.turtles[i].id; }
};

}  // namespace turtlegas::formats
