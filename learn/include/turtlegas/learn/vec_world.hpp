// SPDX-License-Identifier: MIT
// Vectorised worlds for learning: n independent copies of one scene, stepped together by a pool of
// threads, each turtle driven by an action per control step instead of its program.
//
// Order of one control step of one copy, at t = k dt (docs/python.md, "Vectorised worlds"):
//   actions velocity / wheels (a continuous (v, omega) per turtle, each in [-1, 1]):
//   1. At t every live turtle starts a turn of omega * turn_rate * dt / 2 radians (positive:
//      clockwise, Logo's "right"); it takes at most dt / 2 at the turtle's turn rate.
//   2. At t + dt / 2 every live turtle starts a stroke of v * speed * dt / 2 units (negative: back);
//      it takes at most dt / 2 at the turtle's speed, and stops dead at a contact, as every turtle
//      command does (the engine's exact contact; AI Memo 272, "On simulating turtles").
//   So the turtle turns, then drives: the engine has no arcs, and a (v, omega) action is a short
//   turn and a short stroke per control step, at up to half the turtle's turn rate and speed on
//   average. Wheels (l, r) are the differential drive v = (l + r) / 2, omega = (l - r) / 2.
//   actions logo (one integer per turtle): 0 wait, 1 forward, 2 back, 3 left, 4 right, each for
//   the whole control step at the turtle's speed or turn rate.
//   3. At t + dt each turtle's observation is written (ObsLayout): the touch arcs fired by the
//      step's contacts, its range sensors cast now (sim::World::cast_ray's answers, with the
//      sensor's noise and dropout drawn from the copy's own stream), its odometry of the step, its
//      heading, and its position where the world file grants it "gps".
// The copies share nothing: each has its own sim::World and random stream, so the results do not
// depend on the number of threads or on which thread steps which copy.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "turtlegas/sim/world.hpp"
#include "turtlegas/world/scene.hpp"

namespace turtlegas::learn {

/// What one turtle's action is.
enum class ActionKind {
  velocity,  ///< two floats in [-1, 1]: forward speed and turn rate (clockwise), as fractions
  wheels,    ///< two floats in [-1, 1]: left and right wheel speeds, as fractions
  logo,      ///< one integer in [0, 5): wait, forward, back, left, right (LogoAction)
};

/// The discrete actions of ActionKind::logo, each lasting one control step.
enum class LogoAction : std::int32_t { wait = 0, forward = 1, back = 2, left = 3, right = 4 };
inline constexpr std::int32_t logo_action_count = 5;

/// How VecWorld runs.
struct VecWorldOptions {
  std::size_t threads = 0;  ///< threads that step the copies (the caller's included); 0: one per core
  ActionKind actions = ActionKind::velocity;
  /// reset() places the turtles at random free poses in the arena (true) or where the world file
  /// has them (false; then only the random stream of sample_actions depends on the seed).
  bool random_start = true;
  std::uint64_t max_steps = 0;  ///< control steps after which a copy is truncated; 0: never
  sim::Mode mode = sim::Mode::exact;
};

/// Where each part of a turtle's observation lies in its row of obs_size() floats. Every turtle
/// has the same row; a turtle with fewer touch arcs or rays than the widest has its extra entries
/// at 0 (touch) and 1 (range), and one without gps reads 0, 0 there.
struct ObsLayout {
  std::size_t touch = 0, touch_count = 0;  ///< 1 where the arc fired during the step, else 0
  std::size_t range = 0, range_count = 0;  ///< each ray's distance / its range; 1 for nothing within range
  std::size_t odometry = 0;  ///< two: distance driven in the step (units, negative backwards), angle turned (radians, clockwise)
  std::size_t heading = 0;   ///< two: sin and cos of the heading (Logo: 0 is +y, clockwise)
  std::size_t gps = 0;       ///< two: x and y (world units), only when gps_count is 1
  std::size_t gps_count = 0;  ///< 1 when some turtle of the world has "gps", else 0
  std::size_t size = 0;       ///< floats per turtle
};

/// n copies of a scene, stepped together. Not copyable; one caller thread at a time.
class VecWorld {
 public:
  /// Copies `scene`'s bodies and the turtles' sensors; ignores their programs (the actions drive
  /// them). Throws std::invalid_argument for n = 0 or a scene without turtles.
  VecWorld(const world::Scene& scene, std::size_t n, VecWorldOptions options = {});
  ~VecWorld();
  VecWorld(const VecWorld&) = delete;
  VecWorld& operator=(const VecWorld&) = delete;

  std::size_t size() const;            ///< the number of copies
  std::size_t turtle_count() const;    ///< turtles per copy
  std::size_t thread_count() const;
  const ObsLayout& layout() const;
  std::size_t obs_size() const { return layout().size; }
  /// Floats per turtle per step: 2 (velocity, wheels) or 1 integer (logo).
  std::size_t action_size() const;
  const VecWorldOptions& options() const;
  /// The turtles' ids, in world-file order.
  const std::vector<std::string>& turtle_ids() const;
  double dt() const;  ///< the control step, seconds (the world file's dt)
  /// Each turtle's top speed, units/s (the world file's "speed"), in turtle_ids() order.
  std::vector<double> turtle_speeds() const;

  /// Rebuilds every copy from the scene: copy i draws its start poses and its action stream from
  /// seed and i alone. Writes the first observations to obs (size() * turtle_count() * obs_size()
  /// floats, copy-major). Throws std::runtime_error if a random start finds no free pose.
  void reset(std::uint64_t seed, std::span<float> obs);
  /// Rebuilds copy i alone (as reset does for it) and writes its rows of obs.
  void reset_one(std::size_t i, std::uint64_t seed, std::span<float> obs);

  /// One control step of every copy that is not done (terminated or truncated; a done copy stands
  /// until it is reset, its observations rewritten as they are). actions: size() * turtle_count() *
  /// action_size() floats for velocity and wheels (clamped to [-1, 1]; NaN reads as 0). Writes obs,
  /// and per copy terminated (a turtle left the world: crushed, or out of an open arena) and
  /// truncated (max_steps reached). Throws std::invalid_argument for wrong sizes or action kind.
  void step(std::span<const float> actions, std::span<float> obs, std::span<std::uint8_t> terminated,
            std::span<std::uint8_t> truncated);
  /// As step, for ActionKind::logo: one LogoAction value per turtle (out of range: wait).
  void step(std::span<const std::int32_t> actions, std::span<float> obs, std::span<std::uint8_t> terminated,
            std::span<std::uint8_t> truncated);

  /// Random valid actions, uniform, from each copy's own stream (seeded by reset).
  void sample_actions(std::span<float> out);
  void sample_actions(std::span<std::int32_t> out);

  /// Copy i's engine, for its state (positions, stats) between steps.
  const sim::World& world(std::size_t i) const;
  /// Control steps copy i has taken since its reset.
  std::uint64_t steps(std::size_t i) const;
  /// Contacts involving turtles in copy i's last step (each contact counted once per turtle).
  std::uint64_t last_contacts(std::size_t i) const;

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace turtlegas::learn
