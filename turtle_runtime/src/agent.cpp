// SPDX-License-Identifier: MIT
// The Agent's side of a command (issue, deliver) and the Turtle API's bodies: what a controller's
// calls do, on the program's own stack.
#include "agent.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <spdlog/spdlog.h>

#include "sensors.hpp"
#include "server_impl.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/sim/format.hpp"

namespace turtlegas::turtle {

void Agent::not_own_program() const {
  throw std::logic_error("turtle '" + id + "': commands must be issued from its own program");
}

// A command's whole round trip on the program's stack is kept shallow: every line of stack the
// program touches between two commands is a cache miss at each resume once there are thousands of
// turtles. So the scheduler does the bookkeeping of a finished command on its own (warm) stack
// before resuming (WorldServer::Impl::finish_command), and this side only hands the answer back,
// running the handlers out of line when there is something for them.
Result Agent::issue(sim::TurtleCommand c) {
  if (!fiber || detail::Fiber::current() != &*fiber) [[unlikely]] not_own_program();
  if (ending) [[unlikely]] refuse_while_ending(c);
  command = c;
  waiting_on = c.kind;
  waiting = true;
  // The wall pen lays the stroke this command drives, in the pen mode it was issued in.
  lays_wall = pen_down && pen_mode == PenMode::wall && c.kind == sim::TurtleCommand::Kind::move;
  if (lays_wall) stroke_start = server->world.turtle(index).pos;
  fiber->suspend();
  // Resumed by the scheduler: the command has ended. The answer is taken first, since a handler's
  // own command leaves the next one; then interrupts, then messages.
  Result r = std::move(answer);
  if (!inbox.empty() || !messages.empty()) [[unlikely]] deliver();
  return r;
}

void Agent::end_program() {
  if (!fiber) return;
  if (!fiber->done()) {
    ending = true;
    const double budget = server->options.program_budget;
    using Outcome = detail::Fiber::Outcome;
    switch (fiber->stop(budget)) {
      case Outcome::finished:
      case Outcome::suspended: break;  // unwound, or refused with refuse_while_ending's warning
      case Outcome::stack_overflow:
        spdlog::warn("turtle '{}': its program overflowed its stack while the run was ending; it was abandoned", id);
        break;
      case Outcome::over_budget:
        spdlog::warn("turtle '{}': its program ran for more than {} s without a command while the run was ending (a "
                     "catch (...) that swallows the unwinding, then a loop?); it was abandoned",
                     id, budget);
        break;
    }
  }
  fiber.reset();
}

void Agent::refuse_while_ending(sim::TurtleCommand c) {
  static constexpr const char* names[] = {"yield", "forward/back", "left/right", "wait"};
  spdlog::warn("turtle '{}': its program issued a command ({}) while the run was ending, after catching the exception "
               "that unwinds it; a catch (...) in a controller must rethrow (docs/controllers.md). The program is "
               "abandoned",
               id, names[static_cast<int>(c.kind)]);
  for (;;) fiber->suspend();  // stop() sees it suspend again and never resumes it
}

void Agent::deliver() {
  std::vector<Touch> delivered;
  delivered.swap(inbox);
  if (handler)
    for (const Touch& t : delivered) handler(t);
  // Hand the buffer back for the next touches (unless a handler's own command refilled the inbox).
  delivered.clear();
  if (inbox.empty()) inbox.swap(delivered);
  std::vector<Message> letters;
  letters.swap(messages);
  if (message_handler)
    for (const Message& m : letters) message_handler(m);
}

// ---------------------------------------------------------------------------------------------
// The controller API

namespace {

// A NaN or infinite amount has no motion to give (forward(NaN) drove 86 units backwards, right(NaN)
// turned 171 degrees): the program faults, naming the call.
[[noreturn, gnu::noinline, gnu::cold]] void bad_amount(const Agent& a, const char* call, double amount,
                                                       const char* what) {
  throw std::invalid_argument("turtle '" + a.id + "': " + call + "(" + sim::format_number(amount) + "): " + what);
}

}  // namespace

// Negative amounts are directions: forward(-d) is back(d) and right(-a) is left(a), as in Logo
// and in the script controller; a wait cannot be negative.
Result Turtle::forward(double distance) {
  if (!std::isfinite(distance)) [[unlikely]] bad_amount(*agent_, "forward", distance, "the distance must be a finite number of units");
  return agent_->issue({sim::TurtleCommand::Kind::move, distance});
}
Result Turtle::back(double distance) {
  if (!std::isfinite(distance)) [[unlikely]] bad_amount(*agent_, "back", distance, "the distance must be a finite number of units");
  return agent_->issue({sim::TurtleCommand::Kind::move, -distance});
}
Result Turtle::right(double degrees) {
  if (!std::isfinite(degrees)) [[unlikely]] bad_amount(*agent_, "right", degrees, "the angle must be a finite number of degrees");
  return agent_->issue({sim::TurtleCommand::Kind::turn, sim::to_radians(degrees)});
}
Result Turtle::left(double degrees) {
  if (!std::isfinite(degrees)) [[unlikely]] bad_amount(*agent_, "left", degrees, "the angle must be a finite number of degrees");
  return agent_->issue({sim::TurtleCommand::Kind::turn, sim::to_radians(-degrees)});
}
Result Turtle::wait(double seconds) {
  if (!(seconds >= 0.0 && std::isfinite(seconds))) [[unlikely]]
    bad_amount(*agent_, "wait", seconds, "the time must be a finite number of seconds >= 0");
  return agent_->issue({sim::TurtleCommand::Kind::wait, seconds});
}
void Turtle::yield() { agent_->issue({sim::TurtleCommand::Kind::stop, 0.0}); }
void Turtle::pen_up() { agent_->pen_down = false; }
void Turtle::pen_down(PenMode mode) {
  if (mode == PenMode::wall && !agent_->program.builder)
    throw std::logic_error("turtle '" + agent_->id +
                           "' may not lay walls: give it \"builder\": true (or \"pen\": \"wall\") in the world file, "
                           "so that the world server can give it a collision category of its own");
  if (!agent_->pen_down) agent_->trail.push_back(agent_->server->world.turtle(agent_->index).pos);
  agent_->pen_down = true;
  agent_->pen_mode = mode;
}
PenMode Turtle::pen_mode() const { return agent_->pen_mode; }
bool Turtle::pen_is_down() const { return agent_->pen_down; }
void Turtle::on_touch(std::function<void(const Touch&)> handler) { agent_->handler = std::move(handler); }
void Turtle::on_message(std::function<void(const Message&)> handler) { agent_->message_handler = std::move(handler); }
bool Turtle::it() const { return agent_->it; }
double Turtle::odometer() const { return agent_->odometer; }
double Turtle::heading() const { return sim::wrap_degrees(sim::to_degrees(agent_->server->world.turtle(agent_->index).heading)); }
std::optional<sim::Vec2> Turtle::position() const {
  if (!agent_->program.gps) return std::nullopt;
  return agent_->server->world.turtle(agent_->index).pos;
}
double Turtle::time() const { return agent_->server->world.time(); }
const std::string& Turtle::id() const { return agent_->id; }
double Turtle::uniform() { return static_cast<double>(agent_->rng() >> 11) * 0x1.0p-53; }
void Turtle::log(const std::string& message) { spdlog::info("turtle '{}' t={:.6g}: {}", agent_->id, time(), message); }

std::vector<Touch> Turtle::touching() const {
  // Contacts in force, with their sensors worked out for the heading the turtle has now.
  std::vector<Touch> out;
  const double heading_deg = sim::to_degrees(agent_->server->world.turtle(agent_->index).heading);
  for (const sim::TurtleContact& c : agent_->in_contact)
    out.push_back(detail::make_touch(c, heading_deg, agent_->program.sensors, agent_->sensor_names,
                                     agent_->server->other_id(c.kind, c.other)));
  return out;
}

}  // namespace turtlegas::turtle
