// SPDX-License-Identifier: MIT
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <functional>
#include <utility>
#include <vector>

#include "disc_grid.hpp"
#include "turtlegas/sim/cover_grid.hpp"
#include "turtlegas/sim/format.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim {
namespace {

using Where = DefProblem::Where;

std::string num(double v) { return format_number(v); }
std::string vec(Vec2 v) { return format_vec(v); }

std::string quoted(std::string_view id) {
  std::string s = "'";
  s += id;
  s += '\'';
  return s;
}

std::string ball_name(const BallDef& b, std::size_t i) {
  return b.id.empty() ? "ball #" + std::to_string(i) : "ball " + quoted(b.id);
}

std::string wall_name(const WallDef& w, std::size_t i) {
  return w.id.empty() ? "wall #" + std::to_string(i) : "wall " + quoted(w.id);
}

DefProblem problem(Where where, std::size_t index, std::string field, std::string message) {
  return DefProblem{where, index, std::move(field), std::move(message)};
}

std::optional<DefProblem> check_scalars(const WorldDef& def) {
  if (!std::isfinite(def.dt) || def.dt <= 0.0)
    return problem(Where::world, 0, "dt", "dt must be a finite number of seconds > 0 (got " + num(def.dt) + "); the memo's step is 1/30");

  const ArenaDef& a = def.arena;
  if (!std::isfinite(a.width) || a.width <= 0.0)
    return problem(Where::arena, 0, "width", "arena width must be finite and > 0 (got " + num(a.width) + ")");
  if (!std::isfinite(a.height) || a.height <= 0.0)
    return problem(Where::arena, 0, "height", "arena height must be finite and > 0 (got " + num(a.height) + ")");
  if (a.cell && (!std::isfinite(*a.cell) || *a.cell <= 0.0))
    return problem(Where::arena, 0, "cell", "arena cell must be finite and > 0 (got " + num(*a.cell) + "); leave it out to let the memo's rule choose it");

  const EffectsDef& e = def.effects;
  if (!is_finite(e.gravity))
    return problem(Where::effects, 0, "gravity", "gravity must be finite (got " + vec(e.gravity) + ")");
  if (!is_finite(e.electric))
    return problem(Where::effects, 0, "electric", "electric field must be finite (got " + vec(e.electric) + ")");
  if (!std::isfinite(e.magnetic))
    return problem(Where::effects, 0, "magnetic", "magnetic field must be finite (got " + num(e.magnetic) + ")");
  if (!(e.restitution >= 0.0 && e.restitution <= 1.0))
    return problem(Where::effects, 0, "restitution", "restitution must be in [0, 1] (got " + num(e.restitution) + "); 1 is elastic, 0 perfectly inelastic");
  if (!std::isfinite(e.tc) || e.tc <= 0.0)
    return problem(Where::effects, 0, "tc", "tc must be a finite number of seconds > 0 (got " + num(e.tc) + "); the default is 1e-4");
  return std::nullopt;
}

/// A moving wall's keyframes: times increasing and > 0, finite poses of non-zero length, and
/// between two poses (each end moving in a straight line) a wall that never shrinks to a point.
std::optional<DefProblem> check_keyframes(const WallDef& w, std::size_t i) {
  Vec2 d_prev = w.to - w.from;
  double t_prev = 0.0;
  for (std::size_t k = 0; k < w.keys.size(); ++k) {
    const WallKey& key = w.keys[k];
    const std::string head = wall_name(w, i) + " keyframe " + std::to_string(k) + ": ";
    if (!std::isfinite(key.t) || !(key.t > t_prev))
      return problem(Where::wall, i, "keys", head + "times must be finite, increase and be > 0 (got " + num(key.t) + " after " + num(t_prev) + ")");
    if (!is_finite(key.from) || !is_finite(key.to))
      return problem(Where::wall, i, "keys", head + "from and to must be finite (got " + vec(key.from) + " and " + vec(key.to) + ")");
    const Vec2 d = key.to - key.from;
    if (!(norm(d) > 0.0))
      return problem(Where::wall, i, "keys", head + "the wall has zero length (from and to are both " + vec(key.from) + ")");
    const Vec2 dd = d - d_prev;
    const double s = norm2(dd) > 0.0 ? std::clamp(-dot(d_prev, dd) / norm2(dd), 0.0, 1.0) : 0.0;
    if (!(norm(d_prev + s * dd) > 1e-9 * std::max(norm(d_prev), norm(d))))
      return problem(Where::wall, i, "keys", head + "on the way to this pose the wall would shrink to a point (its ends pass through each other); add a keyframe in between");
    d_prev = d;
    t_prev = key.t;
  }
  return std::nullopt;
}

/// A wall in a periodic arena: both ends inside it (the engine's table wraps bodies, not walls),
/// and fixed (moving walls are not supported there yet).
std::optional<DefProblem> check_periodic_wall(const WallDef& w, std::size_t i, const ArenaDef& a) {
  for (const auto& [field, p] : {std::pair<const char*, Vec2>{"from", w.from}, {"to", w.to}})
    if (!inside_arena(a, p))
      return problem(Where::wall, i, field,
                     wall_name(w, i) + " reaches outside a periodic arena (its end " + field + " " + vec(p) +
                         " is not in [0, " + num(a.width) + "] x [0, " + num(a.height) +
                         "]); keep walls inside it");
  if (!w.keys.empty())
    return problem(Where::wall, i, "keys",
                   wall_name(w, i) + " moves: moving walls are not supported in a periodic arena yet; "
                                     "remove its keys or use boundary \"walls\" or \"none\"");
  return std::nullopt;
}

/// Visibility keys: times increasing and >= 0.
std::optional<DefProblem> check_visibility(const WallDef& w, std::size_t i) {
  double prev = -1.0;
  for (std::size_t k = 0; k < w.visibility.size(); ++k) {
    const double t = w.visibility[k].t;
    if (!(t > prev) || t < 0.0)
      return problem(Where::wall, i, "visible",
                     wall_name(w, i) + " visibility key " + std::to_string(k) +
                         ": times must increase and be >= 0 (got " + num(t) +
                         (k > 0 ? " after " + num(prev) : std::string()) + ")");
    prev = t;
  }
  return std::nullopt;
}

std::optional<DefProblem> check_walls(const WorldDef& def) {
  for (std::size_t i = 0; i < def.walls.size(); ++i) {
    const WallDef& w = def.walls[i];
    if (!is_finite(w.from))
      return problem(Where::wall, i, "from", wall_name(w, i) + ": from must be finite (got " + vec(w.from) + ")");
    if (!is_finite(w.to))
      return problem(Where::wall, i, "to", wall_name(w, i) + ": to must be finite (got " + vec(w.to) + ")");
    if (w.from == w.to)
      return problem(Where::wall, i, "to", wall_name(w, i) + " has zero length (from and to are both " + vec(w.from) + "); move one end or remove the wall");
    if (auto p = check_keyframes(w, i)) return p;
    if (def.arena.boundary == Boundary::periodic)
      if (auto p = check_periodic_wall(w, i, def.arena)) return p;
    if (auto p = check_visibility(w, i)) return p;
  }
  return std::nullopt;
}

/// Balls and turtles are both discs: numbered balls first, then turtles, for the checks that
/// treat them alike (inside the arena, unique ids, overlaps).
struct Discs {
  const WorldDef& def;
  std::size_t size() const { return def.balls.size() + def.turtles.size(); }
  bool is_ball(std::size_t k) const { return k < def.balls.size(); }
  Vec2 pos(std::size_t k) const { return is_ball(k) ? def.balls[k].pos : def.turtles[k - def.balls.size()].pos; }
  double radius(std::size_t k) const {
    return is_ball(k) ? def.balls[k].radius : def.turtles[k - def.balls.size()].radius;
  }
  const std::string& id(std::size_t k) const {
    return is_ball(k) ? def.balls[k].id : def.turtles[k - def.balls.size()].id;
  }
  Where where(std::size_t k) const { return is_ball(k) ? Where::ball : Where::turtle; }
  const Layers& layers(std::size_t k) const {
    return is_ball(k) ? def.balls[k].layers : def.turtles[k - def.balls.size()].layers;
  }
  std::size_t index(std::size_t k) const { return is_ball(k) ? k : k - def.balls.size(); }
  std::string name(std::size_t k) const {
    const char* noun = is_ball(k) ? "ball" : "turtle";
    return id(k).empty() ? std::string(noun) + " #" + std::to_string(index(k)) : std::string(noun) + " " + quoted(id(k));
  }
  DefProblem problem(std::size_t k, std::string field, std::string message) const {
    return DefProblem{where(k), index(k), std::move(field), std::move(message)};
  }
};

std::optional<DefProblem> check_placement(const Discs& d, std::size_t k) {
  const ArenaDef& a = d.def.arena;
  const Vec2 p = d.pos(k);
  const double r = d.radius(k);
  const std::string arena_box = "[0, " + num(a.width) + "] x [0, " + num(a.height) + "]";
  if (a.boundary == Boundary::walls) {
    if (p.x - r < 0.0 || p.x + r > a.width || p.y - r < 0.0 || p.y + r > a.height)
      return d.problem(k, "pos",
                       d.name(k) + " (radius " + num(r) + ") at " + vec(p) +
                           " sticks out of the arena walls; the whole disc must lie in " + arena_box +
                           ", so move it inside or make it smaller");
  } else if (p.x < 0.0 || p.x > a.width || p.y < 0.0 || p.y > a.height) {
    return d.problem(k, "pos",
                     d.name(k) + " at " + vec(p) + " is outside the arena " + arena_box +
                         "; move its centre inside or enlarge the arena");
  }
  if (a.boundary == Boundary::periodic && (2.0 * r >= a.width || 2.0 * r >= a.height))
    return d.problem(k, "radius",
                     d.name(k) + " (radius " + num(r) +
                         ") would touch its own periodic image; its diameter must be smaller than the arena's width and height");
  return std::nullopt;
}

/// The times of impact of two discs square their relative speed times their distance ((r x v)^2
/// and sigma^2 v^2 in toi_disc_disc); above sqrt(DBL_MAX) = 1.34e154 those overflow, the root is
/// NaN, and the pair passes through each other without a word. A relative speed is at most twice
/// the fastest body's, a distance at most the arena's diagonal (a uniform field changes no
/// relative velocity of two balls), so 2 |v| diagonal must stay below this, a quarter under.
constexpr double kSpeedTimesSize = 1e154;

std::optional<DefProblem> check_speed(const WorldDef& def, Where where, std::size_t i, const std::string& name,
                                      const char* key, double speed) {
  const double diagonal = std::hypot(def.arena.width, def.arena.height);
  if (2.0 * speed * diagonal < kSpeedTimesSize) return std::nullopt;
  return problem(where, i, key,
                 name + ": a speed of " + num(speed) + " units/s is beyond what the engine can time in this arena (the " +
                     "times of impact square twice the speed times the arena's diagonal, " + num(diagonal) +
                     ", and must stay below " + num(kSpeedTimesSize) + "): at most " +
                     num(kSpeedTimesSize / (2.0 * diagonal)) + " units/s here");
}

std::optional<DefProblem> check_balls(const WorldDef& def) {
  const Discs d{def};
  for (std::size_t i = 0; i < def.balls.size(); ++i) {
    const BallDef& b = def.balls[i];
    if (!is_finite(b.pos))
      return problem(Where::ball, i, "pos", ball_name(b, i) + ": pos must be finite (got " + vec(b.pos) + ")");
    if (!is_finite(b.vel))
      return problem(Where::ball, i, "vel", ball_name(b, i) + ": vel must be finite (got " + vec(b.vel) + ")");
    if (!std::isfinite(b.radius) || b.radius <= 0.0)
      return problem(Where::ball, i, "radius", ball_name(b, i) + ": radius must be > 0 (got " + num(b.radius) + ")");
    if (!std::isfinite(b.mass) || b.mass <= 0.0)
      return problem(Where::ball, i, "mass", ball_name(b, i) + ": mass must be > 0 (got " + num(b.mass) + ")");
    if (!std::isfinite(b.charge))
      return problem(Where::ball, i, "charge", ball_name(b, i) + ": charge must be finite (got " + num(b.charge) + ")");
    if (auto p = check_speed(def, Where::ball, i, ball_name(b, i), "vel", std::hypot(b.vel.x, b.vel.y))) return p;
    if (auto p = check_placement(d, i)) return p;
  }
  return std::nullopt;
}

/// A rotating or deforming wall under a magnetic field, with charged balls: no solver meets a
/// gyrating ball with a turning segment (a translating wall is a fixed one in its own frame, with
/// the field E + u x B there, and is served).
std::optional<DefProblem> check_field_walls(const WorldDef& def) {
  if (def.effects.magnetic == 0.0) return std::nullopt;
  const bool charged = std::any_of(def.balls.begin(), def.balls.end(), [](const BallDef& b) { return b.charge != 0.0; });
  if (!charged) return std::nullopt;
  for (std::size_t i = 0; i < def.walls.size(); ++i) {
    const WallDef& w = def.walls[i];
    Vec2 d_prev = w.to - w.from;
    for (std::size_t k = 0; k < w.keys.size(); ++k) {
      const Vec2 d = w.keys[k].to - w.keys[k].from;
      if (!(d == d_prev))
        return problem(Where::wall, i, "keys",
                       wall_name(w, i) + " keyframe " + std::to_string(k) +
                           " turns or stretches the wall, which effects.magnetic with charged balls does not support "
                           "(exact flights meet only fixed and translating walls under a magnetic field); keep to - from "
                           "the same in every keyframe, or set effects.magnetic to 0");
      d_prev = d;
    }
  }
  return std::nullopt;
}

std::optional<DefProblem> check_turtles(const WorldDef& def) {
  const Discs d{def};
  for (std::size_t i = 0; i < def.turtles.size(); ++i) {
    const TurtleDef& t = def.turtles[i];
    const std::size_t k = def.balls.size() + i;
    const std::string name = d.name(k);
    if (!is_finite(t.pos)) return problem(Where::turtle, i, "pos", name + ": pos must be finite (got " + vec(t.pos) + ")");
    if (!std::isfinite(t.heading))
      return problem(Where::turtle, i, "heading", name + ": heading must be finite (got " + num(t.heading) + ")");
    if (!std::isfinite(t.radius) || t.radius <= 0.0)
      return problem(Where::turtle, i, "radius", name + ": radius must be > 0 (got " + num(t.radius) + ")");
    if (!std::isfinite(t.speed) || t.speed <= 0.0)
      return problem(Where::turtle, i, "speed", name + ": speed must be > 0 units/s (got " + num(t.speed) + ")");
    if (auto p = check_speed(def, Where::turtle, i, name, "speed", t.speed)) return p;
    if (!std::isfinite(t.turn_rate) || t.turn_rate <= 0.0)
      return problem(Where::turtle, i, "turn_rate", name + ": turn_rate must be > 0 (got " + num(t.turn_rate) + " rad/s)");
    if (!std::isfinite(t.bounce) || t.bounce > 1.0)
      return problem(Where::turtle, i, "bounce",
                     name + ": bounce must be negative (stop dead at a contact, the memo's model) or a restitution in [0, 1] (got " +
                         num(t.bounce) + ")");
    if (auto p = check_placement(d, k)) return p;
  }
  return std::nullopt;
}

const std::array<std::string_view, 4> arena_ids = {"arena-bottom", "arena-right", "arena-top", "arena-left"};

std::optional<DefProblem> check_ids(const WorldDef& def) {
  // Every named object in a fixed order: the arena's walls (boundary walls only), walls, then
  // balls and turtles. Empty ids are anonymous (scenes built in code need not name anything); the
  // loader requires them.
  const Discs d{def};
  const std::size_t arena_n = def.arena.boundary == Boundary::walls ? arena_ids.size() : 0;
  const std::size_t total = arena_n + def.walls.size() + d.size();
  auto id_of = [&](std::size_t k) -> std::string_view {
    if (k < arena_n) return arena_ids[k];
    k -= arena_n;
    if (k < def.walls.size()) return def.walls[k].id;
    return d.id(k - def.walls.size());
  };
  auto describe = [&](std::size_t k) -> std::string {
    if (k < arena_n) return "the arena wall of boundary \"walls\"";
    k -= arena_n;
    if (k < def.walls.size()) return "wall #" + std::to_string(k);
    k -= def.walls.size();
    return (d.is_ball(k) ? "ball #" : "turtle #") + std::to_string(d.index(k));
  };

  // Open addressing over object numbers + 1 (0 is empty): a million ids in a few tens of ms, where
  // a node-based map spends most of its time in the allocator.
  std::size_t size = 16;
  while (size < 2 * total) size *= 2;
  std::vector<std::uint32_t> table(size, 0);
  const std::hash<std::string_view> hash;
  for (std::size_t k = 0; k < total; ++k) {
    const std::string_view id = id_of(k);
    if (id.empty()) continue;
    for (std::size_t slot = hash(id) & (size - 1);; slot = (slot + 1) & (size - 1)) {
      if (table[slot] == 0) {
        table[slot] = static_cast<std::uint32_t>(k + 1);
        break;
      }
      if (id_of(table[slot] - 1) != id) continue;
      const std::string message = "duplicate id " + quoted(id) + " (already used by " + describe(table[slot] - 1) +
                                  "); every object needs its own id";
      const std::size_t i = k - arena_n;
      if (i < def.walls.size()) return problem(Where::wall, i, "id", message);
      return d.problem(i - def.walls.size(), "id", message);
    }
  }
  return std::nullopt;
}

/// Calls visit(centre, item) for every item of `grid` near each of a disc's images (`count`
/// centres in img, radius r: the disc and, in a periodic arena, its copies across the edges it
/// crosses), the images in order; stops as soon as visit returns true, and says whether it did.
template <class Grid, class Visit>
bool for_each_image_hit(const Grid& grid, const std::array<Vec2, 4>& img, int count, double r, const Visit& visit) {
  for (int m = 0; m < count; ++m) {
    const Vec2 p = img[m];
    if (grid.any(grid.cover_disc(p, r), [&](std::uint32_t item) { return visit(p, item); })) return true;
  }
  return false;
}

/// Disc-disc and disc-wall overlaps. Disc pairs in cells of 4 median radii: one grid over the
/// arena where such cells fit, otherwise hashed cells where the discs are (DiscGrid, however
/// large the arena); discs against walls with one grid over the arena
/// grown by the largest radius (so every disc lies inside it), walls entered in every cell their
/// segment crosses, discs looking in every cell their bounding box covers. A pair that overlaps
/// shares at least one cell. In a periodic arena a disc that crosses an edge is also entered (and
/// tested) at its shifted images.
/// Two balls may overlap when ball-ball collisions are off, and any two objects whose collision
/// layers do not meet may overlap (they pass through each other).
std::optional<DefProblem> check_overlaps(const WorldDef& def) {
  const Discs d{def};
  const std::size_t n = d.size();
  if (n == 0) return std::nullopt;
  const ArenaDef& a = def.arena;
  const bool periodic = a.boundary == Boundary::periodic;

  double r_max = 0.0;
  std::vector<double> radii(n);
  for (std::size_t k = 0; k < n; ++k) {
    radii[k] = d.radius(k);
    r_max = std::max(r_max, radii[k]);
  }
  // Twice the median diameter as cell side: a typical disc covers 1 to 4 cells, and a handful of
  // huge discs cannot make the cells coarse.
  std::nth_element(radii.begin(), radii.begin() + static_cast<std::ptrdiff_t>(n / 2), radii.end());
  const double side = 4.0 * radii[n / 2];
  radii = {};

  const Vec2 lo{-r_max, -r_max};
  const Vec2 hi{a.width + r_max, a.height + r_max};
  const std::size_t max_cells = 4 * (n + def.walls.size()) + 1024;

  // A disc's images: itself and, in a periodic arena, its copies shifted across each edge it crosses.
  auto images = [&](std::size_t k, std::array<Vec2, 4>& out) -> int {
    const Vec2 p = d.pos(k);
    const double r = d.radius(k);
    out[0] = p;
    if (!periodic) return 1;
    double sx = 0.0, sy = 0.0;
    if (p.x - r < 0.0) sx = a.width;
    else if (p.x + r > a.width) sx = -a.width;
    if (p.y - r < 0.0) sy = a.height;
    else if (p.y + r > a.height) sy = -a.height;
    int m = 1;
    if (sx != 0.0) out[m++] = p + Vec2{sx, 0.0};
    if (sy != 0.0) out[m++] = p + Vec2{0.0, sy};
    if (sx != 0.0 && sy != 0.0) out[m++] = p + Vec2{sx, sy};
    return m;
  };

  const bool balls_collide = def.effects.ball_ball;
  if (balls_collide || !def.turtles.empty()) {
    // Items are disc * 4 + image, so a periodic pair is caught from whichever side crosses the edge.
    std::array<Vec2, 4> img{}, other{};
    // Whether disc k's image at p overlaps the image `item` of another disc it collides with.
    auto overlaps = [&](std::size_t k, Vec2 p, std::uint32_t item) {
      const std::size_t j = item / 4;
      if (j == k) return false;
      if (!balls_collide && d.is_ball(j) && d.is_ball(k)) return false;
      if (!d.layers(j).collides_with(d.layers(k))) return false;
      Vec2 q = d.pos(j);
      if (item % 4 != 0) {
        images(j, other);
        q = other[item % 4];
      }
      const double s = d.radius(k) + d.radius(j);
      return norm2(p - q) < s * s;
    };
    // The pair reported is the one whose later disc comes first, with its earliest partner.
    std::optional<std::pair<std::size_t, std::size_t>> first;  // (later, earlier)
    auto note = [&](std::size_t k, std::size_t j) {
      const std::pair<std::size_t, std::size_t> pair{std::max(j, k), std::min(j, k)};
      if (!first || pair < *first) first = pair;
    };
    const double cells = std::ceil((hi.x - lo.x) / side) * std::ceil((hi.y - lo.y) / side);
    if (cells <= static_cast<double>(max_cells)) {
      // Cells of the side asked for fit over the arena: one grid over it, each disc checked
      // against those before it (the fastest for a gas that fills its arena: no sort).
      CoverGrid grid(lo, hi, side, max_cells);
      // Room for every entry first: a list grown by doubling would briefly hold three times as many.
      std::size_t entries = 0;
      for (std::size_t k = 0; k < n; ++k)
        for (int m = 0, m_count = images(k, img); m < m_count; ++m) entries += grid.cover_disc(img[m], d.radius(k)).cells();
      grid.reserve(entries);
      for (std::size_t k = 0; k < n && !first; ++k) {
        const int m_count = images(k, img);
        const double r = d.radius(k);
        for_each_image_hit(grid, img, m_count, r, [&](Vec2 p, std::uint32_t item) {
          if (overlaps(k, p, item)) note(k, item / 4);
          return false;
        });
        for (int m = 0; m < m_count; ++m)
          grid.insert(grid.cover_disc(img[m], r), static_cast<std::uint32_t>(k * 4 + static_cast<std::size_t>(m)));
      }
    } else {
      // The arena is too large for such cells (an arena grid would be coarsened, and 1e5 discs
      // clustered in a 1e9 arena shared one cell: O(N^2)): the discs' own cells, hashed
      // (disc_grid.hpp). A pair is seen from the disc at the lower level of that grid (or from
      // both), so once disc k is done every pair whose later disc is at most k has been seen.
      DiscGrid grid(side);
      std::size_t entries = 0;
      for (std::size_t k = 0; k < n; ++k) entries += 4 * static_cast<std::size_t>(images(k, img));
      grid.reserve(entries);
      for (std::size_t k = 0; k < n; ++k)
        for (int m = 0, m_count = images(k, img); m < m_count; ++m)
          grid.add(img[m], d.radius(k), static_cast<std::uint32_t>(k * 4 + static_cast<std::size_t>(m)));
      grid.build();
      for (std::size_t k = 0; k < n && !(first && first->first < k); ++k)
        for_each_image_hit(grid, img, images(k, img), d.radius(k), [&](Vec2 p, std::uint32_t item) {
          if (overlaps(k, p, item)) note(k, item / 4);
          return false;
        });
    }
    if (first) {
      const auto [k, j] = *first;
      return d.problem(k, "pos",
                       d.name(k) + " at " + vec(d.pos(k)) + " overlaps " + d.name(j) + " at " + vec(d.pos(j)) +
                           " (radii " + num(d.radius(k)) + " + " + num(d.radius(j)) +
                           "); move them apart or make them smaller");
    }
  }

  if (def.walls.empty()) return std::nullopt;
  CoverGrid walls_grid(lo, hi, side, max_cells);
  for (std::size_t w = 0; w < def.walls.size(); ++w)
    walls_grid.insert_segment(def.walls[w].from, def.walls[w].to, static_cast<std::uint32_t>(w));
  std::array<Vec2, 4> img{};
  for (std::size_t k = 0; k < n; ++k) {
    const int m_count = images(k, img);
    const double r = d.radius(k);
    std::optional<std::size_t> hit;
    for_each_image_hit(walls_grid, img, m_count, r, [&](Vec2 p, std::uint32_t w) {
      const WallDef& wall = def.walls[w];
      if (!wall.layers.collides_with(d.layers(k))) return false;
      if (segment_distance2(p, wall.from, wall.to) < r * r) hit = w;
      return hit.has_value();
    });
    if (hit) {
      const WallDef& wall = def.walls[*hit];
      return d.problem(k, "pos",
                       d.name(k) + " (radius " + num(r) + ") at " + vec(d.pos(k)) + " overlaps " + wall_name(wall, *hit) +
                           " from " + vec(wall.from) + " to " + vec(wall.to) +
                           "; move it away from the wall or make it smaller");
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<DefProblem> validate(const WorldDef& def) {
  if (auto p = check_scalars(def)) return p;
  if (auto p = check_walls(def)) return p;
  if (auto p = check_balls(def)) return p;
  if (auto p = check_field_walls(def)) return p;
  if (auto p = check_turtles(def)) return p;
  // Bodies, and wall ends (two per wall, the arena's four included), are indexed with 29 bits.
  const std::size_t bodies = def.balls.size() + def.turtles.size();
  const std::size_t wall_ends = 2 * (def.walls.size() + arena_ids.size());
  if (bodies > kMaxObjects || wall_ends > kMaxObjects)
    return problem(Where::world, 0, bodies > kMaxObjects ? "balls" : "walls",
                   "too many objects (" + std::to_string(bodies) + " balls and turtles, " + std::to_string(def.walls.size()) +
                       " walls); the engine indexes them with 29 bits: at most " + std::to_string(kMaxObjects) +
                       " balls and turtles, and " + std::to_string(kMaxObjects / 2 - arena_ids.size()) + " walls");
  if (auto p = check_ids(def)) return p;
  if (auto p = check_overlaps(def)) return p;
  return std::nullopt;
}

std::vector<WallDef> arena_walls(const ArenaDef& arena) {
  const double w = arena.width, h = arena.height;
  return {
      WallDef{std::string(arena_ids[0]), {0.0, 0.0}, {w, 0.0}},
      WallDef{std::string(arena_ids[1]), {w, 0.0}, {w, h}},
      WallDef{std::string(arena_ids[2]), {w, h}, {0.0, h}},
      WallDef{std::string(arena_ids[3]), {0.0, h}, {0.0, 0.0}},
  };
}

WallKey wall_pose(const WallDef& wall, double t) {
  WallKey prev{0.0, wall.from, wall.to};
  for (const WallKey& k : wall.keys) {
    if (t < k.t) {
      const double s = (t - prev.t) / (k.t - prev.t);
      return {t, prev.from + s * (k.from - prev.from), prev.to + s * (k.to - prev.to)};
    }
    prev = k;
  }
  return {t, prev.from, prev.to};
}

bool inside_arena(const ArenaDef& arena, Vec2 p) {
  return !(p.x < 0.0 || p.x > arena.width || p.y < 0.0 || p.y > arena.height);
}

bool wall_visible(const WallDef& wall, double t) {
  bool visible = true;
  for (const VisibilityKey& k : wall.visibility)
    if (!(k.t > t)) visible = k.visible;
  return visible;
}

}  // namespace turtlegas::sim
