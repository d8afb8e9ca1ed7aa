// SPDX-License-Identifier: MIT
// The world server's state: the scene, the engine, the agents, the event log and the game. The
// scheduler's steps are world_server.cpp's; laying walls is builder_walls.cpp's.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "agent.hpp"
#include "sensors.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/sim/control_steps.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/turtle/event_names.hpp"
#include "turtlegas/turtle/game.hpp"
#include "turtlegas/turtle/remote.hpp"
#include "turtlegas/turtle/view.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::turtle {

class WorldServer::Impl : public GameHost {
 public:
  sim::WorldDef def;
  sim::World world;
  ServerOptions options;
  std::vector<std::unique_ptr<Agent>> agents;
  std::vector<sim::Event> sim_log;
  std::vector<LogEvent>* log = nullptr;
  std::unique_ptr<Game> game;
  std::vector<std::uint32_t> idle;  // control_step's candidates, kept for their capacity
  std::uint64_t step = 0;        // index of the next control boundary
  bool boundary_done = false;    // whether the programs have run at boundary `step`
  WorldServer* self = nullptr;   // for the InputSource's at_boundary
  std::vector<RemoteReport> reports;  // the remote programs' reports, until flush_reports()
  std::vector<View> views;             // the open views (view.cpp), in opening order
  std::uint64_t views_revision = 0;
  Colours colours;     // what cameras see (senses.cpp)
  Registry registry;  // a copy of the constructor's: the programs of turtles spawned later

  Impl(sim::WorldDef d, ServerOptions o) : def(std::move(d)), world(def, o.mode), options(std::move(o)) {}

  /// The agent of turtle k (def.turtles[k]) running `program`; throws std::invalid_argument for
  /// a controller that is not registered or bad sensor arcs.
  std::unique_ptr<Agent> make_agent(std::size_t k, TurtleProgram program, const std::vector<std::string>& turtle_ids);
  /// Throws std::logic_error unless called from InputSource::at_boundary (what: the caller's name).
  void require_boundary(const char* what) const;
  double boundary_time(std::uint64_t k) const { return sim::control_boundary(k, def.dt); }
  void control_step();
  void run_program(Agent& a);
  /// One turn of a's program; true when it is a remote program to be resumed again at once.
  bool resume(Agent& a);
  // Remote turtles (remote.cpp).
  /// Whether to resume remote agent a now: it has touches or messages to take, or the
  /// InputSource gave it a command. Flushes the reports first, so a lockstep client has them.
  bool feed_remote(Agent& a);
  void flush_reports();
  /// A report of agent a, with the turtle's state as its program sees it now.
  RemoteReport report_of(const Agent& a, RemoteReport::Kind kind) const;
  void finish_command(Agent& a);
  void drain_sim_events();
  void lay_wall(Agent& a, sim::Vec2 from, sim::Vec2 to);
  /// The pen along the arc that just ended in state s: its chords into the trail (a line pen) or
  /// laid as walls, those of its first lap (a wall pen). builder_walls.cpp.
  void pen_arc(Agent& a, const sim::TurtleState& s);
  bool id_taken(const std::string& id) const;
  void emit(LogEvent e) {
    if (log) log->push_back(std::move(e));
  }
  /// Ids by index, for the event namer (event_names.hpp).
  struct Names {
    const Impl& s;
    std::string_view ball(std::size_t i) const { return s.def.balls[i].id; }
    std::string_view wall(std::size_t i) const { return s.world.walls()[i].id; }
    std::string_view turtle(std::size_t i) const { return s.def.turtles[i].id; }
  };
  Names names() const { return {*this}; }
  /// The id of a turtle contact's other body.
  std::string_view other_id(sim::EventKind kind, std::uint32_t other) const { return other_body(kind, other, names()); }

  // GameHost: what a game may do.
  std::size_t turtle_count() const override { return agents.size(); }
  const std::string& turtle_id(std::size_t i) const override { return agents.at(i)->id; }
  void send(std::size_t i, Message m) override {
    Agent& a = *agents.at(i);
    if (!a.finished) a.messages.push_back(std::move(m));
  }
  void set_it(std::size_t i, bool it) override { agents.at(i)->it = it; }
  void log_event(LogEvent e) override { emit(std::move(e)); }
};

inline Touch Agent::make_touch(const sim::TurtleContact& c) const {
  return detail::make_touch(c, sim::to_degrees(server->world.turtle(index).heading), program.sensors, sensor_names,
                            server->other_id(c.kind, c.other));
}

}  // namespace turtlegas::turtle
