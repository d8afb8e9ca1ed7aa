// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "turtlegas/sim/vec2.hpp"

namespace turtlegas::sim {

/// What happens at the arena's edges.
enum class Boundary {
  none,      ///< the arena only bounds the grid; a ball whose centre leaves it is removed (`exit`)
  walls,     ///< four walls on the edges (ids `arena-bottom`, `arena-right`, `arena-top`, `arena-left`)
  periodic,  ///< opposite edges are identified
};

/// How time advances.
enum class Mode {
  exact,  ///< continuous-time, event-driven; analytic flights under fields
  step,   ///< the memo's algorithm: fixed dt, earliest collision first inside a step, field kicks between steps
};

/// The rectangle (0,0)-(width,height) that the grid covers.
struct ArenaDef {
  double width = 1600.0;   ///< world units
  double height = 1600.0;  ///< world units
  /// Requested grid cell side in world units; empty chooses it by the memo's rule.
  std::optional<double> cell;
  Boundary boundary = Boundary::none;
};

/// The physics a scene asks for. Anything left at its default costs nothing at run time.
struct EffectsDef {
  Vec2 gravity{};            ///< uniform acceleration, units/s^2
  Vec2 electric{};           ///< uniform field; acceleration charge/mass * E (not simulated yet)
  double magnetic = 0.0;     ///< field normal to the plane (not simulated yet)
  double restitution = 1.0;  ///< e in [0, 1]: the memo's "2 replaced by 1+e"
  bool ball_ball = true;     ///< whether balls collide with each other
  /// Inelastic-collapse threshold t_c in seconds (see docs/physics.md): a ball-ball collision of a
  /// ball whose previous collision was less than t_c ago is elastic (the TC rule, used only when
  /// restitution < 1), and a ball pressed onto a wall or wall end by gravity never leaves it slower
  /// than g_n t_c / 2, so it hops for at least t_c (the rest threshold).
  double tc = 1e-4;
};

/// Collision layers. Every wall, ball and turtle is in some categories and collides with some;
/// two objects collide when each is in a category the other collides with:
/// `(a.category & b.mask) != 0 && (b.category & a.mask) != 0`. The defaults make everything
/// collide with everything. A wall "not really there" for a turtle leaves the turtle's category
/// out of its mask; an invisible turtle collides only with walls (mask = the walls' category).
struct Layers {
  std::uint32_t category = 1;       ///< bit set: the categories this object is in
  std::uint32_t mask = 0xffffffffu;  ///< bit set: the categories it collides with
  bool operator==(const Layers&) const = default;
  bool collides_with(const Layers& o) const { return (category & o.mask) != 0 && (o.category & mask) != 0; }
};

/// A moving wall's pose at a time (seconds).
struct WallKey {
  double t = 0.0;
  Vec2 from;
  Vec2 to;
};

/// From time t (seconds) on, a wall is there (visible) or not really there (for everything).
struct VisibilityKey {
  double t = 0.0;
  bool visible = true;
};

/// A line-segment wall. Its two ends are collision objects of their own.
struct WallDef {
  std::string id;
  Vec2 from;  ///< the pose at t = 0
  Vec2 to;
  Layers layers{};
  /// Empty: the wall is fixed. Otherwise it moves through these poses (times increasing, > 0),
  /// each end in a straight line at constant speed from one pose to the next, and stays at the
  /// last: it may translate, turn and stretch (but not shrink to a point on the way). Not in
  /// periodic arenas.
  std::vector<WallKey> keys{};
  /// Empty: always there. Otherwise times (increasing, >= 0) from which the wall is there or not;
  /// before the first it is there. A wall that appears through a body lets it out (only
  /// approaching bodies collide). Works with the wall's layers: "not there" ignores everyone.
  std::vector<VisibilityKey> visibility{};
};

/// A disc ("ball", a gas molecule).
struct BallDef {
  std::string id;
  Vec2 pos;            ///< centre, world units
  Vec2 vel;            ///< units/s
  double radius = 1.0;
  double mass = 1.0;
  double charge = 0.0;
  Layers layers{};
};

/// A turtle's body: a disc that moves only as its program commands (see World::command_turtle).
/// Fields do not act on turtles: they drive on the floor of the plane.
struct TurtleDef {
  std::string id;
  Vec2 pos;
  double heading = 0.0;           ///< radians, Logo convention: 0 points to +y, clockwise positive
  double radius = 10.0;           ///< world units
  double speed = 30.0;            ///< forward speed, units/s
  double turn_rate = 1.5707963267948966;  ///< radians/s
  /// Negative (the default): the turtle stops dead at a contact (the memo's model). In [0, 1]: it
  /// bounces off with this restitution instead and coasts until the next control step.
  double bounce = -1.0;
  Layers layers{};
};

/// A whole scene, independent of any file format.
struct WorldDef {
  std::string name;
  std::uint64_t seed = 1;
  double dt = 1.0 / 30.0;  ///< step of `step` mode, seconds (the memo's 1/30 s)
  ArenaDef arena;
  EffectsDef effects;
  std::vector<WallDef> walls;
  std::vector<BallDef> balls;
  std::vector<TurtleDef> turtles;
};

/// A problem with a WorldDef, naming the offending object.
struct DefProblem {
  enum class Where { world, arena, effects, wall, ball, turtle };
  Where where = Where::world;
  std::size_t index = 0;  ///< index into walls, balls or turtles, when `where` is one of them
  std::string field;      ///< the offending field ("radius", "pos", ...), may be empty
  std::string message;    ///< one line, says what is wrong and how to fix it
};

/// The most bodies (balls and turtles together) a scene may have, and the most wall ends (two per
/// wall, the arena's four included): the engine packs an object's index in 29 bits.
inline constexpr std::size_t kMaxObjects = std::size_t{1} << 29;

/// Checks a scene for everything the engine relies on: finite numbers, positive radii and masses,
/// non-zero-length walls, keyframes and visibility keys in order, in a periodic arena walls inside
/// it and fixed, unique ids, balls inside the arena and not overlapping each other or a wall,
/// restitution in [0, 1], no more than kMaxObjects bodies or wall ends. (The engine's own checks
/// are those that depend on the mode: the cell size, and what a step may hold.) Returns the first problem found, if any. O(N) expected time.
std::optional<DefProblem> validate(const WorldDef& def);

/// The arena walls that `Boundary::walls` adds, in the order and with the ids the engine uses.
std::vector<WallDef> arena_walls(const ArenaDef& arena);

/// Where a wall is at time t (seconds): its pose interpolated between keyframes as the engine
/// moves it (each end linearly), the last pose after the last keyframe; from/to if it is fixed.
WallKey wall_pose(const WallDef& wall, double t);

/// Whether point p lies in the closed rectangle [0, width] x [0, height] of the arena (a periodic
/// arena's walls must: validate() and World::add_wall check both ends).
bool inside_arena(const ArenaDef& arena, Vec2 p);

/// Whether a wall is there at time t (its visibility keys; always, if it has none).
bool wall_visible(const WallDef& wall, double t);

}  // namespace turtlegas::sim
