// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "turtlegas/sim/engine_state.hpp"
#include "turtlegas/sim/ray_cast.hpp"
#include "turtlegas/sim/world.hpp"

namespace turtlegas::sim::detail {

/// What World forwards to; one implementation per combination of physics (see engine.hpp; the variants are listed in factory.cpp).
class EngineBase {
 public:
  virtual ~EngineBase() = default;
  virtual void advance_to(double t) = 0;
  /// An exact copy of the whole engine (World::copy), logging nowhere.
  virtual std::unique_ptr<EngineBase> clone() const = 0;
  /// World::can_save_state, save_state and restore_state (saved_state.hpp).
  virtual bool can_save_state() const = 0;
  virtual EngineState save_state() const = 0;
  virtual void restore_state(const EngineState& state) = 0;
  virtual void set_event_log(std::vector<Event>* log) = 0;
  virtual void set_impulse_log(std::vector<Impulse>* log) = 0;
  virtual void set_event_limit(std::uint64_t limit) = 0;
  virtual void set_stop_poll(std::function<bool()> poll, std::uint64_t every) = 0;
  virtual double time() const = 0;
  virtual std::size_t ball_count() const = 0;
  virtual BallState ball(std::size_t i) const = 0;
  virtual double radius(std::size_t i) const = 0;
  virtual double mass(std::size_t i) const = 0;
  virtual const std::vector<WallDef>& walls() const = 0;
  virtual double energy() const = 0;
  virtual const Stats& stats() const = 0;
  virtual const std::vector<double>& energy_taken() const = 0;
  virtual Overlap measure_overlap() const = 0;
  virtual Overlap max_contact_overlap() const = 0;
  virtual std::size_t turtle_count() const = 0;
  virtual TurtleState turtle(std::size_t i) const = 0;
  virtual double turtle_radius(std::size_t i) const = 0;
  virtual void idle_turtles(std::vector<std::uint32_t>& out) const = 0;
  virtual void prefetch_turtle(std::size_t i) const = 0;
  virtual void command_turtle(std::size_t i, const TurtleCommand& command) = 0;
  virtual std::vector<TurtleContact> take_turtle_contacts() = 0;
  virtual std::size_t add_wall(const WallDef& wall) = 0;
  virtual std::size_t spawn_ball(const BallDef& ball) = 0;
  virtual std::size_t spawn_turtle(const TurtleDef& turtle) = 0;
  virtual void remove_body(bool turtle, std::size_t index) = 0;
  virtual void teleport_ball(std::size_t i, Vec2 pos, Vec2 vel) = 0;
  virtual void teleport_turtle(std::size_t i, Vec2 pos, double heading) = 0;
  virtual bool turtle_alive(std::size_t i) const = 0;
  virtual void balls_in_rect(Vec2 lo, Vec2 hi, std::vector<std::uint32_t>& out) const = 0;
  virtual RayHit cast_ray(const Ray& ray) const = 0;
  virtual void cast_rays(const Ray& ray, const Vec2* dirs, std::size_t n, RayHit* out) const = 0;
  virtual double cell_size() const = 0;
  virtual int cells_x() const = 0;
  virtual int cells_y() const = 0;
  virtual Mode mode() const = 0;
  virtual double dt() const = 0;
};

std::unique_ptr<EngineBase> make_engine(const WorldDef& def, Mode mode);
/// The same engine; def.balls is freed as soon as the engine has copied it (see World(WorldDef&&)).
std::unique_ptr<EngineBase> make_engine(WorldDef&& def, Mode mode);

}  // namespace turtlegas::sim::detail
