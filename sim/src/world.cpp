// SPDX-License-Identifier: MIT
#include "turtlegas/sim/world.hpp"

#include <utility>

#include "engine/engine_base.hpp"

namespace turtlegas::sim {

class World::Impl {
 public:
  std::unique_ptr<detail::EngineBase> engine;
};

World::World(const WorldDef& def, Mode mode) : impl_(std::make_unique<Impl>()) {
  impl_->engine = detail::make_engine(def, mode);
}
World::World(WorldDef&& def, Mode mode) : impl_(std::make_unique<Impl>()) {
  impl_->engine = detail::make_engine(std::move(def), mode);
}
World::World(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
World World::copy() const {
  auto impl = std::make_unique<Impl>();
  impl->engine = impl_->engine->clone();
  return World(std::move(impl));
}
bool World::can_save_state() const { return impl_->engine->can_save_state(); }
EngineState World::save_state() const { return impl_->engine->save_state(); }
void World::restore_state(const EngineState& state) { impl_->engine->restore_state(state); }
World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

void World::advance_to(double t) { impl_->engine->advance_to(t); }
void World::set_event_log(std::vector<Event>* log) { impl_->engine->set_event_log(log); }
void World::set_impulse_log(std::vector<Impulse>* log) { impl_->engine->set_impulse_log(log); }
void World::set_event_limit(std::uint64_t limit) { impl_->engine->set_event_limit(limit); }
void World::set_stop_poll(std::function<bool()> poll, std::uint64_t every) {
  impl_->engine->set_stop_poll(std::move(poll), every);
}
double World::time() const { return impl_->engine->time(); }
Mode World::mode() const { return impl_->engine->mode(); }
double World::dt() const { return impl_->engine->dt(); }
double World::cell_size() const { return impl_->engine->cell_size(); }
int World::cells_x() const { return impl_->engine->cells_x(); }
int World::cells_y() const { return impl_->engine->cells_y(); }
std::size_t World::ball_count() const { return impl_->engine->ball_count(); }
BallState World::ball(std::size_t i) const { return impl_->engine->ball(i); }
double World::radius(std::size_t i) const { return impl_->engine->radius(i); }
double World::mass(std::size_t i) const { return impl_->engine->mass(i); }
const std::vector<WallDef>& World::walls() const { return impl_->engine->walls(); }
std::size_t World::add_wall(const WallDef& wall) { return impl_->engine->add_wall(wall); }
std::size_t World::spawn_ball(const BallDef& ball) { return impl_->engine->spawn_ball(ball); }
std::size_t World::spawn_turtle(const TurtleDef& turtle) { return impl_->engine->spawn_turtle(turtle); }
void World::remove_ball(std::size_t i) { impl_->engine->remove_body(false, i); }
void World::remove_turtle(std::size_t i) { impl_->engine->remove_body(true, i); }
void World::teleport_ball(std::size_t i, Vec2 pos, Vec2 vel) { impl_->engine->teleport_ball(i, pos, vel); }
void World::teleport_turtle(std::size_t i, Vec2 pos, double heading) {
  impl_->engine->teleport_turtle(i, pos, heading);
}
RayHit World::cast_ray(const Ray& ray) const { return impl_->engine->cast_ray(ray); }
void World::cast_rays(const Ray& ray, const Vec2* dirs, std::size_t n, std::vector<RayHit>& out) const {
  out.resize(n);
  impl_->engine->cast_rays(ray, dirs, n, out.data());
}
void World::balls_in_rect(Vec2 lo, Vec2 hi, std::vector<std::uint32_t>& out) const {
  impl_->engine->balls_in_rect(lo, hi, out);
}
bool World::turtle_alive(std::size_t i) const { return impl_->engine->turtle_alive(i); }
std::size_t World::turtle_count() const { return impl_->engine->turtle_count(); }
TurtleState World::turtle(std::size_t i) const { return impl_->engine->turtle(i); }
double World::turtle_radius(std::size_t i) const { return impl_->engine->turtle_radius(i); }
void World::idle_turtles(std::vector<std::uint32_t>& out) const { impl_->engine->idle_turtles(out); }
void World::prefetch_turtle(std::size_t i) const { impl_->engine->prefetch_turtle(i); }
void World::command_turtle(std::size_t i, const TurtleCommand& command) { impl_->engine->command_turtle(i, command); }
std::vector<TurtleContact> World::take_turtle_contacts() { return impl_->engine->take_turtle_contacts(); }
double World::energy() const { return impl_->engine->energy(); }
const Stats& World::stats() const { return impl_->engine->stats(); }
const std::vector<double>& World::energy_taken() const { return impl_->engine->energy_taken(); }
Overlap World::measure_overlap() const { return impl_->engine->measure_overlap(); }
Overlap World::max_contact_overlap() const { return impl_->engine->max_contact_overlap(); }

}  // namespace turtlegas::sim
