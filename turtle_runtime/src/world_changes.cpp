// SPDX-License-Identifier: MIT
// Bodies added, removed and moved at a control boundary (WorldServer::spawn_ball and the
// others): the engine's operations (sim::World::spawn_ball ...) with ids, programs and events.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "agent.hpp"
#include "server_impl.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/sim/format.hpp"

namespace turtlegas::turtle {
namespace {

/// The engine's refusal with the obstacle named by its id.
[[noreturn]] void refuse(const WorldServer::Impl& s, const std::string& who, const sim::PlacementError& e) {
  using Obstacle = sim::PlacementError::Obstacle;
  std::string what;
  switch (e.obstacle) {
    case Obstacle::ball: what = "ball '" + s.def.balls[e.index].id + "'"; break;
    case Obstacle::turtle: what = "turtle '" + s.def.turtles[e.index].id + "'"; break;
    case Obstacle::wall: what = "wall '" + s.world.walls()[e.index].id + "'"; break;
    case Obstacle::none: throw std::invalid_argument(who + ": " + e.what());
  }
  throw std::invalid_argument(who + " would overlap " + what + " by " + sim::format_number(e.depth) +
                              " (world units); place it clear of it");
}

/// The checks of a world-file entry (validate()'s messages, naming the entry by its id).
void check_entry(const WorldServer::Impl& s, sim::WorldDef one) {
  one.arena = s.def.arena;
  one.arena.cell.reset();
  one.dt = s.def.dt;
  if (auto problem = sim::validate(one)) throw std::invalid_argument(problem->message);
}

}  // namespace

void WorldServer::Impl::require_boundary(const char* what) const {
  if (boundary_done || world.time() != boundary_time(step))
    throw std::logic_error(std::string(what) + ": call it from InputSource::at_boundary, at a control boundary");
}

std::optional<std::string> WorldServer::placement_problem(sim::Vec2 pos, double radius, const std::string& self) const {
  const Impl& s = *impl_;
  const sim::Layers plain{};
  const sim::ArenaDef& a = s.def.arena;
  const bool periodic = a.boundary == sim::Boundary::periodic;
  auto image = [&](sim::Vec2 d) {
    if (periodic) {
      d.x -= a.width * std::round(d.x / a.width);
      d.y -= a.height * std::round(d.y / a.height);
    }
    return d;
  };
  auto overlap = [&](const std::string& what, double depth) {
    return "it would overlap " + what + " by " + sim::format_number(depth) + " (world units); place it clear of it";
  };
  for (const sim::WallDef& w : s.world.walls()) {
    if (!w.layers.collides_with(plain)) continue;
    const sim::Vec2 u = w.to - w.from;
    const double len2 = sim::dot(u, u);
    const sim::Vec2 rel = image(pos - w.from);
    const double f = len2 > 0 ? std::clamp(sim::dot(rel, u) / len2, 0.0, 1.0) : 0.0;
    const double gap = sim::norm(rel - f * u) - radius;
    if (gap < 0.0) return overlap("wall '" + w.id + "'", -gap);
  }
  for (std::size_t i = 0; i < s.world.ball_count(); ++i) {
    const sim::BallState b = s.world.ball(i);
    if (!b.alive || s.def.balls[i].id == self || !s.def.balls[i].layers.collides_with(plain)) continue;
    const double gap = sim::norm(image(b.pos - pos)) - (s.world.radius(i) + radius);
    if (gap < 0.0) return overlap("ball '" + s.def.balls[i].id + "'", -gap);
  }
  for (std::size_t k = 0; k < s.world.turtle_count(); ++k) {
    if (!s.world.turtle_alive(k) || s.def.turtles[k].id == self || !s.def.turtles[k].layers.collides_with(plain)) continue;
    const double gap = sim::norm(image(s.world.turtle(k).pos - pos)) - (s.world.turtle_radius(k) + radius);
    if (gap < 0.0) return overlap("turtle '" + s.def.turtles[k].id + "'", -gap);
  }
  return std::nullopt;
}

const sim::WorldDef& WorldServer::scene() const { return impl_->def; }

std::optional<bool> WorldServer::body_is_ball(const std::string& id) const {
  const Impl& s = *impl_;
  for (std::size_t i = 0; i < s.def.balls.size(); ++i)
    if (s.def.balls[i].id == id) return s.world.ball(i).alive ? std::optional<bool>(true) : std::nullopt;
  for (std::size_t i = 0; i < s.def.turtles.size(); ++i)
    if (s.def.turtles[i].id == id) return s.world.turtle_alive(i) ? std::optional<bool>(false) : std::nullopt;
  return std::nullopt;
}

std::size_t WorldServer::spawn_ball(const sim::BallDef& ball) {
  Impl& s = *impl_;
  s.require_boundary("spawn_ball");
  if (ball.id.empty()) throw std::invalid_argument("a ball needs an id");
  if (s.id_taken(ball.id))
    throw std::invalid_argument("id '" + ball.id + "' is taken; give the ball an id that no wall, ball or turtle has");
  sim::WorldDef one;
  one.balls.push_back(ball);
  check_entry(s, std::move(one));
  std::size_t i = 0;
  try {
    i = s.world.spawn_ball(ball);
  } catch (const sim::PlacementError& e) {
    refuse(s, "ball '" + ball.id + "'", e);
  }
  s.def.balls.push_back(ball);
  s.emit({s.world.time(), "spawn", ball.id, "ball", {}, 0.0, {}, {}, {}});
  return i;
}

std::size_t WorldServer::spawn_turtle(const sim::TurtleDef& turtle, TurtleProgram program) {
  Impl& s = *impl_;
  s.require_boundary("spawn_turtle");
  if (turtle.id.empty()) throw std::invalid_argument("a turtle needs an id");
  if (s.id_taken(turtle.id))
    throw std::invalid_argument("id '" + turtle.id + "' is taken; give the turtle an id that no wall, ball or turtle has");
  if (program.builder || program.pen_walls)
    throw std::invalid_argument("turtle '" + turtle.id +
                                "': a builder (a wall pen) needs a collision category of its own, given before the "
                                "run; put it in the world file");
  sim::WorldDef one;
  one.turtles.push_back(turtle);
  check_entry(s, std::move(one));
  // The program first (an unknown controller changes nothing), then the body.
  const std::size_t k = s.agents.size();
  s.def.turtles.push_back(turtle);
  std::unique_ptr<Agent> agent;
  try {
    std::vector<std::string> ids;
    for (const auto& t : s.def.turtles) ids.push_back(t.id);
    agent = s.make_agent(k, std::move(program), ids);
    const std::size_t index = s.world.spawn_turtle(turtle);
    if (index != k) throw std::logic_error("spawn_turtle: the engine's turtle index is not the runtime's");
  } catch (const sim::PlacementError& e) {
    s.def.turtles.pop_back();
    refuse(s, "turtle '" + turtle.id + "'", e);
  } catch (...) {
    s.def.turtles.pop_back();
    throw;
  }
  s.agents.push_back(std::move(agent));
  s.emit({s.world.time(), "spawn", turtle.id, "turtle", {}, 0.0, {}, {}, {}});
  return k;
}

void WorldServer::remove_body(const std::string& id) {
  Impl& s = *impl_;
  s.require_boundary("remove");
  const std::optional<bool> ball = body_is_ball(id);
  if (!ball) throw std::invalid_argument("no ball or turtle '" + id + "' is in the world; name one that is");
  if (*ball) {
    std::size_t i = 0;
    while (s.def.balls[i].id != id) ++i;
    s.world.remove_ball(i);
  } else {
    std::size_t k = 0;
    while (s.def.turtles[k].id != id) ++k;
    Agent& a = *s.agents[k];
    // The program is unwound first, while everything it may use is alive, then the body goes.
    a.end_program();
    a.finished = true;
    a.waiting = a.wants_input = a.lays_wall = false;
    a.command.reset();
    a.inbox.clear();
    a.messages.clear();
    a.in_contact.clear();
    s.world.remove_turtle(k);
  }
  s.emit({s.world.time(), "remove", id, *ball ? "ball" : "turtle", {}, 0.0, {}, {}, {}});
}

void WorldServer::teleport_ball(const std::string& id, sim::Vec2 pos, sim::Vec2 vel) {
  Impl& s = *impl_;
  s.require_boundary("teleport");
  const std::optional<bool> ball = body_is_ball(id);
  if (!ball || !*ball) throw std::invalid_argument("no ball '" + id + "' is in the world; name one that is");
  std::size_t i = 0;
  while (s.def.balls[i].id != id) ++i;
  sim::BallDef d = s.def.balls[i];
  d.pos = pos;
  d.vel = vel;
  sim::WorldDef one;
  one.balls.push_back(d);
  check_entry(s, std::move(one));
  try {
    s.world.teleport_ball(i, pos, vel);
  } catch (const sim::PlacementError& e) {
    refuse(s, "ball '" + id + "'", e);
  }
  s.emit({s.world.time(), "teleport", id, "ball", {}, 0.0, {}, {}, {}});
}

void WorldServer::teleport_turtle(const std::string& id, sim::Vec2 pos, double heading_deg) {
  Impl& s = *impl_;
  s.require_boundary("teleport");
  const std::optional<bool> ball = body_is_ball(id);
  if (!ball || *ball) throw std::invalid_argument("no turtle '" + id + "' is in the world; name one that is");
  std::size_t k = 0;
  while (s.def.turtles[k].id != id) ++k;
  if (!std::isfinite(heading_deg)) throw std::invalid_argument("turtle '" + id + "': heading must be finite");
  sim::TurtleDef d = s.def.turtles[k];
  d.pos = pos;
  d.heading = sim::to_radians(sim::wrap_degrees(heading_deg));
  sim::WorldDef one;
  one.turtles.push_back(d);
  check_entry(s, std::move(one));
  const sim::Vec2 was = s.world.turtle(k).pos;
  try {
    s.world.teleport_turtle(k, pos, d.heading);
  } catch (const sim::PlacementError& e) {
    refuse(s, "turtle '" + id + "'", e);
  }
  Agent& a = *s.agents[k];
  a.in_contact.clear();  // what it touched is where it was
  if (a.pen_down) {  // the stroke ends where it was; the next starts here, no line between
    a.trail.push_back(was);
    a.trail.push_back(trail_break);
    a.trail.push_back(pos);
  }
  s.emit({s.world.time(), "teleport", id, "turtle", {}, 0.0, {}, {}, {}});
}

}  // namespace turtlegas::turtle
