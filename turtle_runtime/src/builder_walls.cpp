// SPDX-License-Identifier: MIT
// Wall-laying turtles: the private collision category each builder gets, and the walls its pen
// lays while the world runs.
#include <algorithm>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <string>

#include <spdlog/spdlog.h>

#include "pen_chords.hpp"
#include "server_impl.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::turtle {

sim::WorldDef with_builder_layers(sim::WorldDef def, const std::vector<TurtleProgram>& programs) {
  std::uint32_t used = 0;
  for (const auto& w : def.walls) used |= w.layers.category;
  for (const auto& b : def.balls) used |= b.layers.category;
  for (const auto& t : def.turtles) used |= t.layers.category;
  const std::size_t n = std::min(programs.size(), def.turtles.size());
  for (std::size_t k = 0; k < n; ++k) {
    if (!programs[k].builder) continue;
    // Free bits from the top down, away from the world file's named categories (bit 0 upwards).
    int bit = 31;
    while (bit >= 0 && ((used >> bit) & 1u) != 0) --bit;
    if (bit < 0)
      throw std::invalid_argument("turtle '" + def.turtles[k].id +
                                  "' lays walls but no collision category is free for it (32 in use); use fewer "
                                  "category names or fewer builder turtles");
    const std::uint32_t own = std::uint32_t{1} << bit;
    used |= own;
    sim::TurtleDef& builder = def.turtles[k];
    // Whoever collided with the builder's categories collides with its private one too, so moving
    // it there changes nothing but its own walls (whose mask leaves `own` out).
    const std::uint32_t was = builder.layers.category;
    auto widen = [&](sim::Layers& l) {
      if ((l.mask & was) != 0) l.mask |= own;
    };
    for (auto& w : def.walls) widen(w.layers);
    for (auto& b : def.balls) widen(b.layers);
    for (std::size_t j = 0; j < def.turtles.size(); ++j)
      if (j != k) widen(def.turtles[j].layers);
    builder.layers.category = own;
  }
  return def;
}

bool WorldServer::Impl::id_taken(const std::string& id) const {
  for (const auto& w : world.walls())
    if (w.id == id) return true;
  for (const auto& b : def.balls)
    if (b.id == id) return true;
  for (const auto& t : def.turtles)
    if (t.id == id) return true;
  return false;
}

void WorldServer::Impl::lay_wall(Agent& a, sim::Vec2 from, sim::Vec2 to) {
  const double now = world.time();
  sim::WallDef w;
  do w.id = a.id + "-w" + std::to_string(a.walls_laid++);
  while (id_taken(w.id));
  w.from = from;
  w.to = to;
  // In the default category, colliding with everything except the builder's private category.
  w.layers.category = 1;
  w.layers.mask = ~def.turtles[a.index].layers.category;
  try {
    world.add_wall(w);
  } catch (const std::invalid_argument& e) {
    spdlog::warn("turtle '{}' t={:.6g}: wall {} not laid: {}", a.id, now, w.id, e.what());
    emit({now, "wall-refused", a.id, w.id, {}, 0.0, e.what(), {}, {}});
    return;
  }
  emit({now, "wall-drawn", a.id, w.id, {}, 0.0, {}, {}, {}});
}

void WorldServer::Impl::pen_arc(Agent& a, const sim::TurtleState& s) {
  const sim::TurtleCommand& c = a.stroke;
  // The turn so far: its rate times the time driven (the distance along the arc over the speed).
  const double turned = c.speed != 0.0 ? c.rate * (s.done / std::abs(c.speed)) : 0.0;
  const std::vector<sim::Vec2> chords =
      detail::arc_chords(a.stroke_start, a.stroke_heading, c.speed, c.rate, turned, s.pos, def.turtles[a.index].radius);
  if (a.pen_down) a.trail.insert(a.trail.end(), chords.begin(), chords.end());
  if (!a.lays_wall) return;
  // Walls for the first lap only: the chords of later laps would lie on walls already laid. Past a
  // lap, the last chord within it is closed back to the start.
  constexpr double lap = 2.0 * std::numbers::pi;
  const double per_chord = std::abs(detail::drawn_turn(turned)) / static_cast<double>(chords.size());
  sim::Vec2 from = a.stroke_start;
  std::size_t k = 0;
  for (; k < chords.size() && static_cast<double>(k + 1) * per_chord <= lap * (1.0 + 1e-12); ++k) {
    if (chords[k] != from) lay_wall(a, from, chords[k]);
    from = chords[k];
  }
  // (Not when the first lap ended on the start, up to round-off: a wall of no length.)
  const double r = std::abs(c.speed / c.rate);
  if (k < chords.size() && norm(from - a.stroke_start) > 1e-9 * r) lay_wall(a, from, a.stroke_start);
}

void WorldServer::add_wall(const sim::WallDef& wall) {
  Impl& s = *impl_;
  if (wall.id.empty()) throw std::invalid_argument("a wall needs an id");
  if (s.id_taken(wall.id))
    throw std::invalid_argument("id '" + wall.id + "' is taken; give the wall an id that no wall, ball or turtle has");
  s.world.add_wall(wall);  // throws std::invalid_argument, changing nothing
  s.emit({s.world.time(), "wall-added", wall.id, {}, {}, 0.0, {}, {}, {}});
}

}  // namespace turtlegas::turtle
