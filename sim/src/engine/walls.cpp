// SPDX-License-Identifier: MIT
#include "walls.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace turtlegas::sim::detail {

Walls::Walls(const WorldDef& def, bool with_layers) {
  defs = def.walls;
  if (def.arena.boundary == Boundary::walls)
    for (auto& w : arena_walls(def.arena)) defs.push_back(w);
  for (const auto& w : defs) segments.push_back(make_segment(w.from, w.to));
  // Moving walls are checked by every prediction rather than listed in the table.
  mover_of.assign(defs.size(), kNone);
  std::uint32_t movers = 0;
  for (std::uint32_t w = 0; w < defs.size(); ++w)
    if (!defs[w].keys.empty()) mover_of[w] = movers++;
  // Wall ends, one per distinct point: a corner shared by two walls is one collision object.
  for (std::uint32_t w = 0; w < defs.size(); ++w)
    if (mover_of[w] == kNone)
      for (Vec2 p : {defs[w].from, defs[w].to}) ends.push_back({p, w});
  std::stable_sort(ends.begin(), ends.end(), [](const WallEnd& a, const WallEnd& b) {
    return a.p.x != b.p.x ? a.p.x < b.p.x : a.p.y < b.p.y;
  });
  ends.erase(std::unique(ends.begin(), ends.end(), [](const WallEnd& a, const WallEnd& b) { return a.p == b.p; }),
             ends.end());
  if (with_layers) {
    for (const auto& w : defs) layers.push_back(w.layers);
    end_layers.assign(ends.size(), Layers{0u, 0u});
    // (Every wall's ends, moving walls' too: a moving wall that starts at a fixed wall's end lends
    // that end its layers until visibility next rebuilds them from the fixed walls.)
    for (const auto& w : defs)
      for (Vec2 p : {w.from, w.to}) add_end_layers(p, w.layers);
  }
}

std::vector<bool> Walls::moving() const {
  std::vector<bool> out(segments.size());
  for (std::uint32_t w = 0; w < segments.size(); ++w) out[w] = mover_of[w] != kNone;
  return out;
}

void Walls::add_end_layers(Vec2 p, const Layers& l) {
  // An end is there for a body if any wall that ends there is.
  for (std::size_t e = 0; e < ends.size(); ++e)
    if (ends[e].p == p) {
      end_layers[e].category |= l.category;
      end_layers[e].mask |= l.mask;
      return;
    }
}

void Walls::rebuild_end_layers() {
  std::fill(end_layers.begin(), end_layers.end(), Layers{0u, 0u});
  for (std::uint32_t w = 0; w < defs.size(); ++w)
    if (mover_of[w] == kNone)
      for (Vec2 p : {defs[w].from, defs[w].to}) add_end_layers(p, layers[w]);
}

void Walls::check_new(const WallDef& wall, const ArenaDef& arena) const {
  const Vec2 d = wall.to - wall.from;
  if (!(norm2(d) > 0.0) || !is_finite(wall.from) || !is_finite(wall.to))
    throw std::invalid_argument("wall '" + wall.id + "' has zero length or a non-finite end; give it two distinct ends");
  if (!wall.keys.empty() || !wall.visibility.empty())
    throw std::invalid_argument("wall '" + wall.id + "': a wall added while the world runs cannot move or come and go (keys, visibility); put it in the scene");
  if (arena.boundary == Boundary::periodic && (!inside_arena(arena, wall.from) || !inside_arena(arena, wall.to)))
    throw std::invalid_argument("wall '" + wall.id + "' reaches outside a periodic arena; keep walls inside it");
  if (2 * (segments.size() + 1) > kMaxObjects)
    throw std::invalid_argument("wall '" + wall.id + "': too many walls (" + std::to_string(segments.size()) +
                                "); the engine indexes wall ends with 29 bits");
}

std::uint32_t Walls::add(const WallDef& wall, bool with_layers) {
  const auto w = static_cast<std::uint32_t>(segments.size());
  defs.push_back(wall);
  segments.push_back(make_segment(wall.from, wall.to));
  for (Vec2 p : {wall.from, wall.to}) {
    const bool known = std::any_of(ends.begin(), ends.end(), [&](const WallEnd& e) { return e.p == p; });
    if (!known) {
      ends.push_back({p, w});
      if (with_layers) end_layers.push_back(Layers{0u, 0u});
    }
  }
  if (with_layers) {
    layers.push_back(wall.layers);
    for (Vec2 p : {wall.from, wall.to}) add_end_layers(p, wall.layers);
  }
  mover_of.push_back(kNone);
  return w;
}

}  // namespace turtlegas::sim::detail
