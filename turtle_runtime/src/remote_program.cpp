// SPDX-License-Identifier: MIT
// Remote turtles (remote.hpp): the remote program, the scheduler's side of feeding it commands
// and passing its reports on, and make_remote (a turtle's program detached at a boundary).
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "agent.hpp"
#include "server_impl.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/turtle/remote.hpp"

namespace turtlegas::turtle {
namespace {

// The remote program: a loop of "take a command, run it as the Turtle API would, report its
// result". Its handlers pass touches and messages on as reports, so that a client hears them in
// the order a C++ program's handlers would (touches, messages, then the command's result).
void remote_program(Agent& a) {
  Turtle t(a);
  t.on_touch([&a](const Touch& touch) {
    RemoteReport r = a.server->report_of(a, RemoteReport::Kind::touch);
    r.touch = touch;
    a.server->reports.push_back(std::move(r));
  });
  t.on_message([&a](const Message& m) {
    RemoteReport r = a.server->report_of(a, RemoteReport::Kind::message);
    r.message = m;
    a.server->reports.push_back(std::move(r));
  });
  std::vector<Reading> readings;
  for (;;) {
    const RemoteCommand c = a.await_remote();
    Result result;
    readings.clear();
    switch (c.kind) {
      case RemoteCommand::Kind::forward: result = t.forward(c.amount); break;
      case RemoteCommand::Kind::back: result = t.back(c.amount); break;
      case RemoteCommand::Kind::left: result = t.left(c.amount); break;
      case RemoteCommand::Kind::right: result = t.right(c.amount); break;
      case RemoteCommand::Kind::wait: result = t.wait(c.amount); break;
      case RemoteCommand::Kind::yield: t.yield(); break;
      case RemoteCommand::Kind::pen_up: t.pen_up(); break;
      case RemoteCommand::Kind::pen_down: t.pen_down(c.pen); break;  // a wall pen without builder throws, as in C++
      case RemoteCommand::Kind::sense: t.scan(c.sensor, readings); break;  // an unknown sensor throws, as in C++
      case RemoteCommand::Kind::camera: t.camera(c.sensor, readings); break;
      case RemoteCommand::Kind::arc: result = t.arc(c.steer[0], c.steer[1]); break;
      case RemoteCommand::Kind::drive: result = t.drive(c.steer[0], c.steer[1], c.steer[2]); break;
      case RemoteCommand::Kind::wheels: result = t.wheels(c.steer[0], c.steer[1], c.steer[2]); break;
    }
    RemoteReport r = a.server->report_of(a, RemoteReport::Kind::result);
    r.command = c;
    r.result = std::move(result);
    r.readings = readings;
    a.server->reports.push_back(std::move(r));
  }
}

}  // namespace

RemoteCommand Agent::await_remote() {
  for (;;) {
    if (remote_input) {
      const RemoteCommand c = *remote_input;
      remote_input.reset();
      return c;
    }
    wants_input = true;
    fiber->suspend();
    wants_input = false;
    // Touches and messages that came while the turtle stood still, before the next command.
    if (!inbox.empty() || !messages.empty()) deliver();
  }
}

bool WorldServer::Impl::feed_remote(Agent& a) {
  flush_reports();
  if (!a.inbox.empty() || !a.messages.empty()) return true;  // resumed to hand them over first
  std::optional<RemoteCommand> c = options.input ? options.input->next(step, a.index) : std::nullopt;
  if (!c) return false;
  a.remote_input = *c;
  return true;
}

void WorldServer::Impl::flush_reports() {
  if (reports.empty()) return;
  if (options.remote_reports)
    for (const RemoteReport& r : reports) options.remote_reports(r);
  reports.clear();
}

RemoteReport WorldServer::Impl::report_of(const Agent& a, RemoteReport::Kind kind) const {
  RemoteReport r;
  r.kind = kind;
  r.turtle = a.index;
  r.step = step;
  r.t = world.time();
  const sim::TurtleState s = world.turtle(a.index);
  r.heading = sim::wrap_degrees(sim::to_degrees(s.heading));  // as Turtle::heading() reads it
  r.odometer = a.odometer;
  if (a.program.gps) r.position = s.pos;
  r.it = a.it;
  r.pen_down = a.pen_down;
  r.pen_mode = a.pen_mode;
  return r;
}

void WorldServer::make_remote(std::size_t i) {
  Impl& s = *impl_;
  Agent& a = *s.agents.at(i);
  if (a.remote) throw std::logic_error("turtle '" + a.id + "' is remote already");
  if (s.boundary_done || s.world.time() != s.boundary_time(s.step))
    throw std::logic_error("make_remote: call it from InputSource::at_boundary, at a control boundary");
  // The old program is unwound first (its handlers may refer to its stack), then forgotten.
  a.fiber.reset();
  a.handler = nullptr;
  a.message_handler = nullptr;
  a.command.reset();
  a.started = a.finished = a.waiting = a.lays_wall = false;
  a.fault.clear();
  a.remote = true;
  a.program.controller = std::string(remote_controller_name);
  a.controller = detail::remote_program_for(a);
  s.world.command_turtle(i, {sim::TurtleCommand::Kind::stop, 0.0});
  s.emit({s.world.time(), "takeover", a.id, {}, {}, 0.0, {}, {}, {}});
}

bool WorldServer::is_remote(std::size_t i) const { return impl_->agents.at(i)->remote; }

namespace detail {

Controller remote_program_for(Agent& a) {
  Agent* agent = &a;
  return [agent](Turtle&, const Params&) { remote_program(*agent); };
}

}  // namespace detail

}  // namespace turtlegas::turtle
