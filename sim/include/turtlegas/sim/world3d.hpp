// SPDX-License-Identifier: MIT
// The 3-D gas (docs/architecture.md, "The 3-D room"; docs/physics.md, "3-D"): spheres, convex
// polygon walls with their faces, edges and corners (standing or translating), uniform gravity,
// electric and magnetic fields, exact and event-driven. The order of work of one event is written at the top of world3d.cpp.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "turtlegas/sim/stops.hpp"
#include "turtlegas/sim/vec3.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim {

/// The arena's boundary on every axis: open (a sphere that leaves is removed, `exit`), six
/// walls on the faces of the box, or periodic.
enum class Boundary3 : std::uint8_t { none, walls, periodic };

struct Sphere3Def {
  Vec3 pos;             ///< world units
  Vec3 vel;             ///< world units per second
  double radius = 1.0;  ///< world units, > 0
  double mass = 1.0;    ///< > 0
  double charge = 0.0;  ///< scales the electric field's acceleration by charge / mass
  /// e in [0, 1], the memo's "2 replaced by 1 + e". A pair takes the larger of its two spheres'
  /// (2-D's rule, which equal e reduces to: the TC rule makes it 1 for a sphere that changed
  /// course less than World3Def::tc ago); a wall contact takes the sphere's e times the wall's.
  double restitution = 1.0;
};

/// A moving wall's pose at a keyframe: its translation from its corners at t = 0.
struct Wall3Key {
  double t = 0.0;  ///< seconds, > 0, increasing along a wall's keys
  Vec3 shift;      ///< world units: every corner at time t is its t = 0 corner plus shift
};

/// A convex planar polygon, corners in order (3 or more, not collinear).
struct Wall3Def {
  std::vector<Vec3> corners;  ///< at t = 0
  double restitution = 1.0;  ///< in [0, 1]; a contact takes this times the sphere's e
  /// A translating wall (docs/physics.md, "3-D: moving walls"): between two keys (and from t = 0
  /// and no shift to the first) it moves at constant velocity; after the last it stays. Empty:
  /// it stands. Not in a periodic arena.
  std::vector<Wall3Key> keys = {};
};

struct World3Def {
  Vec3 size{100.0, 100.0, 100.0};  ///< the arena, from the origin to size (width, height, depth)
  Boundary3 boundary = Boundary3::none;
  Vec3 gravity;   ///< units / s^2, on every sphere
  Vec3 electric;  ///< acceleration charge / mass * electric on each sphere
  /// Uniform B, any direction: a sphere of charge q and mass m feels dv/dt = (q/m) v x B, and flies
  /// a helix (docs/physics.md, "3-D: magnetic fields"). Exact mode only.
  Vec3 magnetic;
  double cell = 0.0;  ///< the grid's smallest cell side; 0: the largest diameter (times 1 + 2^-20)
  /// Inelastic-collapse threshold t_c in seconds (2-D's effects.tc, docs/physics.md "3-D:
  /// restitution"): used only when some e < 1. A pair one of whose spheres changed course less
  /// than t_c ago collides elastically (the TC rule); a sphere pressed onto a wall feature by its
  /// acceleration leaves an inelastic bounce at least at |a_n| t_c / 2 (the rest threshold).
  double tc = 1e-4;
  /// exact: parabolic flights under the fields, every contact at its exact time. step: the memo's
  /// steps of dt (docs/physics.md, "3-D: step mode"): straight flights and every contact exact
  /// within a step, the fields' kick v += a dt at each step's end (drift, then kick, as in 2-D).
  /// Without a field the two modes are the same run.
  Mode mode = Mode::exact;
  double dt = 1.0 / 30.0;  ///< step mode's step, seconds (the world file's dt)
  std::vector<Sphere3Def> spheres;
  std::vector<Wall3Def> walls;  ///< with boundary walls, six more follow these (x0 x1 y0 y1 z0 z1)
};

enum class Event3Kind : std::uint8_t {
  ball_ball,         ///< a, b sphere indices
  ball_wall,         ///< a sphere, b wall index: the face
  ball_wall_edge,    ///< a sphere, b wall index, c the edge (from corner c to corner c + 1)
  ball_wall_corner,  ///< a sphere, b wall index, c the corner
  exit,              ///< a left an open arena
  /// a sphere touching two standing walls on opposite sides lost its velocity between them (the
  /// limit of its zero-time bounces, docs/physics.md "3-D: wedged spheres"): b the wall it met,
  /// c the wall on the other side
  wedged,
};

struct Event3 {
  double t = 0.0;
  Event3Kind kind = Event3Kind::ball_ball;
  std::uint32_t a = 0, b = 0, c = 0;
};

/// Checks a definition; returns an empty string when it can be simulated, else what is wrong
/// and how to fix it. Spheres may touch but not overlap one another, a wall, or (with boundary
/// walls) the arena's faces: an event-driven engine never sees a contact that has already begun.
std::string check_world3(const World3Def& def);

/// The distance from x to the convex polygon `corners` (in order around it): to its plane where
/// the foot of x falls inside it, else to its nearest edge.
double distance_to_polygon(const Vec3& x, const std::vector<Vec3>& corners);

class World3 {
 public:
  /// Builds the world at time 0; throws std::invalid_argument with check_world3's message.
  explicit World3(const World3Def& def);
  ~World3();
  World3(World3&&) noexcept;
  World3& operator=(World3&&) noexcept;

  /// Serves every event up to time t (seconds, >= time()); appends them to log if given. Throws
  /// EventLimitReached or StopRequested (below) with the world consistent at its last event
  /// (time() says when), which the run cannot go on from.
  void advance_to(double t, std::vector<Event3>* log = nullptr);
  /// A bound on the events served (events(), from construction), as World::set_event_limit.
  void set_event_limit(std::uint64_t limit);
  /// `poll` is called after every `every` events served; when it returns true advance_to throws
  /// StopRequested (a signal, a wall clock: the caller's). nullptr removes it.
  void set_stop_poll(std::function<bool()> poll, std::uint64_t every = 4096);
  double time() const;

  std::size_t sphere_count() const;  ///< including removed ones
  bool alive(std::size_t i) const;
  Vec3 position(std::size_t i) const;  ///< at time()
  Vec3 velocity(std::size_t i) const;  ///< at time()
  std::size_t wall_count() const;      ///< the def's walls, then the arena's six

  double kinetic_energy() const;
  /// Kinetic plus potential (-m a . x per sphere, a its uniform acceleration).
  double energy() const;
  Vec3 momentum() const;
  std::uint64_t collisions() const;  ///< sphere-sphere and sphere-wall contacts
  std::uint64_t events() const;      ///< every event served, cell crossings and stale ones included
  /// The largest |distance - contact distance| / radius at the contacts served so far.
  double max_contact_error() const;
  /// The largest overlap now, over every pair and wall, relative to the smaller radius; 0 when
  /// nothing overlaps. O(N) over pairs (an independent hashed grid, engine3d/overlap3.hpp) plus
  /// N x walls, at any N.
  double max_overlap_now() const;
  /// Sum over served sphere-sphere collisions of m1 m2 / (m1 + m2) * (Δv . d): the collision
  /// virial's numerator, for the pressure of a periodic gas (docs/physics.md).
  double virial_sum() const;
  /// The momentum the spheres have pushed into wall w (wall_count() order) since the start:
  /// the sum over its contacts of m Δv . n, n the contact normal towards the sphere. Its rate
  /// over wall_area(w) is the pressure on the wall (docs/observables.md).
  double wall_push(std::size_t w) const;
  double wall_area(std::size_t w) const;  ///< the polygon's area
  /// The wedge rule's count and the kinetic energy it took (docs/physics.md, "3-D: wedged
  /// spheres"): 0 unless a sphere touched two standing walls on opposite sides at once.
  std::uint64_t wedged() const;
  double energy_wedged() const;
  /// The translation of wall w from its t = 0 corners, at time(); zero for a standing wall.
  Vec3 wall_shift(std::size_t w) const;
  /// The kinetic energy moving walls have given the spheres since the start (negative: taken),
  /// booked at each bounce off a moving wall as m/2 (|v'|^2 - |v|^2). With every e = 1,
  /// energy() - its start equals it to round-off (docs/physics.md, "3-D: moving walls").
  double wall_work() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace turtlegas::sim
