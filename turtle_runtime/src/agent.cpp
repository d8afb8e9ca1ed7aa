// SPDX-License-Identifier: MIT
// The Agent's side of a command (issue, deliver) and the Turtle API's bodies: what a controller's
// calls do, on the program's own stack.
#include "agent.hpp"

#include <atomic>
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <spdlog/spdlog.h>

#include "sensors.hpp"
#include "turtlegas/turtle/program_log.hpp"
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
namespace {
// Where a program that has run past its budget without a command is stopped (fiber.hpp): the
// Turtle API's queries, which a loop that polls the world calls.
inline void safe_point() { detail::Fiber::safe_point(); }
}  // namespace

void Agent::throw_gone() const {
  throw TurtleGone("turtle '" + id + "' is no longer in the world (crushed, out of the arena, or removed)");
}

Result Agent::issue(sim::TurtleCommand c) {
  if (!fiber || detail::Fiber::current() != &*fiber) [[unlikely]] not_own_program();
  if (ending) [[unlikely]] refuse_while_ending(c);
  if (gone) [[unlikely]] throw_gone();
  command = c;
  waiting_on = c.kind;
  waiting = true;
  // The wall pen lays the stroke this command drives, in the pen mode it was issued in; on an
  // arc, a lowered pen follows its chords, from where and how it started (pen_chords.hpp).
  const bool arc = c.kind == sim::TurtleCommand::Kind::arc;
  lays_wall = pen_down && pen_mode == PenMode::wall && (c.kind == sim::TurtleCommand::Kind::move || arc);
  if (lays_wall || (pen_down && arc)) [[unlikely]] {
    const sim::TurtleState s = server->world.turtle(index);
    stroke_start = s.pos;
    stroke_heading = s.heading;
    stroke = c;
  }
  fiber->suspend();
  // Resumed by the scheduler: the command has ended. The answer is taken first, since a handler's
  // own command leaves the next one; then interrupts, then messages.
  if (gone) [[unlikely]] throw_gone();
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
  static constexpr const char* names[] = {"yield", "forward/back", "left/right", "wait", "arc/drive/wheels"};
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

/// A call with several arguments that has no motion to give (a NaN, an infinity, a negative
/// time): the program faults, naming the call.
[[noreturn, gnu::noinline, gnu::cold]] void bad_call(const Agent& a, const char* call,
                                                     std::initializer_list<double> args, const char* what) {
  std::string text;
  for (double x : args) text += (text.empty() ? "" : ", ") + sim::format_number(x);
  throw std::invalid_argument("turtle '" + a.id + "': " + call + "(" + text + "): " + what);
}

bool finite(std::initializer_list<double> xs) {
  for (double x : xs)
    if (!std::isfinite(x)) return false;
  return true;
}

/// An arc command: `speed` units/s along the heading while it turns at `rate` rad/s (positive
/// clockwise) for `seconds`; `angle` its exact turn when known (arc()), else NaN.
sim::TurtleCommand arc_command(double speed, double rate, double seconds,
                               double angle = std::numeric_limits<double>::quiet_NaN()) {
  sim::TurtleCommand c;
  c.kind = sim::TurtleCommand::Kind::arc;
  c.amount = seconds;
  c.speed = speed;
  c.rate = rate;
  c.angle = angle;
  return c;
}

}  // namespace

// Negative amounts are directions: forward(-d) is back(d) and right(-a) is left(a), as in Logo
// and in the script controller; a wait cannot be negative. Through a mirror, a right turn is a
// left one (negated exactly, so that mirror twins stay exact).
Result Turtle::forward(double distance) {
  if (!std::isfinite(distance)) [[unlikely]] bad_amount(*agent_, "forward", distance, "the distance must be a finite number of units");
  return seen(agent_->issue({sim::TurtleCommand::Kind::move, distance}));
}
Result Turtle::back(double distance) {
  if (!std::isfinite(distance)) [[unlikely]] bad_amount(*agent_, "back", distance, "the distance must be a finite number of units");
  return seen(agent_->issue({sim::TurtleCommand::Kind::move, -distance}));
}
Result Turtle::right(double degrees) {
  if (!std::isfinite(degrees)) [[unlikely]] bad_amount(*agent_, "right", degrees, "the angle must be a finite number of degrees");
  return seen(agent_->issue({sim::TurtleCommand::Kind::turn, sim::to_radians(mirror_.on ? -degrees : degrees)}));
}
Result Turtle::left(double degrees) {
  if (!std::isfinite(degrees)) [[unlikely]] bad_amount(*agent_, "left", degrees, "the angle must be a finite number of degrees");
  return seen(agent_->issue({sim::TurtleCommand::Kind::turn, sim::to_radians(mirror_.on ? degrees : -degrees)}));
}
Result Turtle::wait(double seconds) {
  if (!(seconds >= 0.0 && std::isfinite(seconds))) [[unlikely]]
    bad_amount(*agent_, "wait", seconds, "the time must be a finite number of seconds >= 0");
  return seen(agent_->issue({sim::TurtleCommand::Kind::wait, seconds}));
}
// Arcs. Degrees at this interface, radians from here on (sim/angles.hpp). Through a mirror the
// turn is negated and the wheels exchanged, exactly, so that mirror twins stay exact.
Result Turtle::arc(double radius, double degrees) {
  if (!(finite({radius, degrees}) && radius >= 0.0)) [[unlikely]]
    bad_call(*agent_, "arc", {radius, degrees},
             "the radius must be a finite number of units >= 0 and the angle a finite number of degrees (positive "
             "turns right, negative left; drive() with a negative speed goes backwards)");
  const sim::TurtleDef& d = agent_->server->def.turtles[agent_->index];
  const double angle = sim::to_radians(mirror_.on ? -degrees : degrees);
  // At the turtle's speed, unless that would turn faster than its turn rate (v = R w): a radius
  // of 0 turns on the spot at the turn rate.
  const double v = std::min(d.speed, d.turn_rate * radius);
  const double w = v > 0.0 ? v / radius : d.turn_rate;
  const double seconds = std::abs(angle) / w;
  return seen(agent_->issue(arc_command(v, std::copysign(w, angle), seconds, angle)));
}
Result Turtle::drive(double v, double omega_degrees_per_s, double seconds) {
  if (!(finite({v, omega_degrees_per_s, seconds}) && seconds >= 0.0)) [[unlikely]]
    bad_call(*agent_, "drive", {v, omega_degrees_per_s, seconds},
             "the speed (units/s) and turn rate (degrees/s) must be finite numbers, the time a finite number of "
             "seconds >= 0");
  const sim::TurtleDef& d = agent_->server->def.turtles[agent_->index];
  const double w = sim::to_radians(mirror_.on ? -omega_degrees_per_s : omega_degrees_per_s);
  // Too fast: both scaled by one factor, so the turtle keeps to the circle it was told.
  double k = 1.0;
  if (std::abs(v) > d.speed) k = d.speed / std::abs(v);
  if (std::abs(w) * k > d.turn_rate) k = d.turn_rate / std::abs(w);
  return seen(agent_->issue(arc_command(k * v, k * w, seconds)));
}
Result Turtle::wheels(double left, double right, double seconds) {
  if (!(finite({left, right, seconds}) && seconds >= 0.0)) [[unlikely]]
    bad_call(*agent_, "wheels", {left, right, seconds},
             "the wheel speeds must be finite numbers of units/s, the time a finite number of seconds >= 0");
  if (mirror_.on) std::swap(left, right);
  const sim::TurtleDef& d = agent_->server->def.turtles[agent_->index];
  // A wheel faster than the turtle's speed: both scaled by one factor (the same circle).
  const double fastest = std::max(std::abs(left), std::abs(right));
  const double k = fastest > d.speed ? d.speed / fastest : 1.0;
  // Differential drive: the centre moves at the wheels' mean, and the heading turns at their
  // difference over the axle (clockwise, Logo's right, when the left wheel is faster).
  return seen(agent_->issue(arc_command(0.5 * (k * left + k * right), (k * left - k * right) / axle(), seconds)));
}
void Turtle::yield() { agent_->issue({sim::TurtleCommand::Kind::stop, 0.0}); }
void Turtle::pen_up() { agent_->pen_down = false; }
void Turtle::pen_down(PenMode mode) {
  if (mode == PenMode::wall && !agent_->program.builder)
    throw std::logic_error("turtle '" + agent_->id +
                           "' may not lay walls: give it \"builder\": true (or \"pen\": \"wall\") in the world file, "
                           "so that the world server can give it a collision category of its own");
  if (!agent_->pen_down) {
    // A new stroke: the last one (if any) ended where the pen went up, not here.
    if (!agent_->trail.empty() && !is_trail_break(agent_->trail.back())) agent_->trail.push_back(trail_break);
    agent_->trail.push_back(agent_->server->world.turtle(agent_->index).pos);
  }
  agent_->pen_down = true;
  agent_->pen_mode = mode;
}
PenMode Turtle::pen_mode() const { return agent_->pen_mode; }
bool Turtle::pen_is_down() const {
  safe_point();
  return agent_->pen_down; }
void Turtle::on_touch(std::function<void(const Touch&)> handler) {
  if (mirror_.on && handler) {
    agent_->handler = [h = std::move(handler), agent = agent_](const Touch& t) { h(reflected(t, *agent)); };
  } else {
    agent_->handler = std::move(handler);
  }
}
void Turtle::on_message(std::function<void(const Message&)> handler) { agent_->message_handler = std::move(handler); }
bool Turtle::it() const {
  safe_point();
  return agent_->it;
}
double Turtle::odometer() const {
  safe_point();
  return agent_->odometer;
}
double Turtle::heading() const {
  safe_point();
  const double h = sim::to_degrees(agent_->server->world.turtle(agent_->index).heading);
  return sim::wrap_degrees(mirror_.on ? 2.0 * mirror_.axis - h : h);
}
std::optional<sim::Vec2> Turtle::position() const {
  safe_point();
  if (!agent_->program.gps) return std::nullopt;
  const sim::Vec2 p = agent_->server->world.turtle(agent_->index).pos;
  if (!mirror_.on) return p;
  if (!mirror_.through) return std::nullopt;
  // Reflected across the line through `through` along the axis: p' = 2 (foot of p) - p.
  const double a = sim::to_radians(mirror_.axis);
  const sim::Vec2 d{std::sin(a), std::cos(a)};
  const sim::Vec2 q = p - *mirror_.through;
  const double along = q.x * d.x + q.y * d.y;
  return sim::Vec2{mirror_.through->x + 2.0 * along * d.x - q.x, mirror_.through->y + 2.0 * along * d.y - q.y};
}
double Turtle::time() const {
  safe_point();
  return agent_->server->world.time();
}
const std::string& Turtle::id() const { return agent_->id; }
double Turtle::uniform() {
  safe_point();
  return static_cast<double>(agent_->rng() >> 11) * 0x1.0p-53; }
namespace {
std::atomic<bool> g_program_logs{true};
}  // namespace

void set_program_logs(bool on) { g_program_logs.store(on, std::memory_order_relaxed); }
bool program_logs() { return g_program_logs.load(std::memory_order_relaxed); }

void Turtle::log(const std::string& message) {
  safe_point();
  if (!program_logs()) return;
  spdlog::info("turtle '{}' t={:.6g}: {}", agent_->id, time(), message); }

double Turtle::radius() const { return agent_->server->def.turtles[agent_->index].radius; }
double Turtle::speed() const { return agent_->server->def.turtles[agent_->index].speed; }
double Turtle::turn_rate() const { return sim::to_degrees(agent_->server->def.turtles[agent_->index].turn_rate); }
double Turtle::axle() const {
  const double a = agent_->program.axle;
  return a > 0.0 ? a : 2.0 * radius();
}
double Turtle::dt() const { return agent_->server->def.dt; }
Display Turtle::display() const { return Display(*agent_); }
nlohmann::json Turtle::game_rules() const {
  return agent_->server->game ? agent_->server->game->rules_for_players() : nlohmann::json::object();
}

std::vector<Touch> Turtle::touching() const {
  safe_point();
  // Contacts in force, with their sensors worked out for the heading the turtle has now.
  std::vector<Touch> out;
  const double heading_deg = sim::to_degrees(agent_->server->world.turtle(agent_->index).heading);
  for (const sim::TurtleContact& c : agent_->in_contact)
    out.push_back(detail::make_touch(c, heading_deg, agent_->program.sensors, agent_->sensor_names,
                                     agent_->server->other_id(c.kind, c.other)));
  if (mirror_.on)
    for (Touch& t : out) t = reflected(t, *agent_);
  return out;
}

Turtle Turtle::mirrored(double axis_degrees, std::optional<sim::Vec2> through) const {
  if (!std::isfinite(axis_degrees) || (through && (!std::isfinite(through->x) || !std::isfinite(through->y))))
    throw std::invalid_argument("Turtle::mirrored: the mirror line's heading and point must be finite numbers");
  Turtle m = *this;
  if (!mirror_.on) {
    m.mirror_ = {true, axis_degrees, through};
    return m;
  }
  // Lines of headings a and a + 180 are the same line.
  if (std::remainder(axis_degrees - mirror_.axis, 180.0) != 0.0)
    throw std::invalid_argument("Turtle::mirrored: a mirrored turtle mirrored across another line is a rotation, not a mirror");
  m.mirror_ = {};
  return m;
}

Touch Turtle::reflected(const Touch& t, const Agent& agent) {
  Touch r = t;
  r.bearing = t.bearing == 0.0 ? 0.0 : 360.0 - t.bearing;  // t.bearing is in [0, 360)
  r.sensors = detail::sensors_for(agent.program.sensors, r.bearing);
  return r;
}

Result Turtle::seen(Result r) const {
  if (!mirror_.on || !r.touched()) return r;
  return Result(r.done(), reflected(r.touch(), *agent_));
}

}  // namespace turtlegas::turtle
