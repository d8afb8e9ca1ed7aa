// SPDX-License-Identifier: MIT
#include "turtlegas/turtle/world_server.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "fiber.hpp"
#include "mt64.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/sim/suggest.hpp"
#include "turtlegas/turtle/game.hpp"

namespace turtlegas::turtle {
namespace {

// FNV-1a: a stable hash, so that per-turtle random streams do not depend on the library.
std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

std::string kind_word(sim::EventKind k) {
  switch (k) {
    case sim::EventKind::turtle_wall: return "wall";
    case sim::EventKind::turtle_wall_end: return "wall-end";
    case sim::EventKind::turtle_turtle: return "turtle";
    case sim::EventKind::turtle_ball: return "ball";
    default: return "?";
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Sensors, registry, the script controller

std::vector<SensorArc> default_sensors() {
  return {{"front", -45, 45}, {"right", 45, 135}, {"back", 135, 225}, {"left", 225, 315}};
}

std::vector<SensorArc> equal_sensors(int n) {
  if (n < 1) throw std::invalid_argument("a turtle needs at least one sensor (got " + std::to_string(n) + ")");
  std::vector<SensorArc> arcs;
  const double w = 360.0 / n;
  for (int k = 0; k < n; ++k) arcs.push_back({"s" + std::to_string(k), k * w - w / 2, k * w + w / 2});
  return arcs;
}

bool Touch::fired(const std::string& sensor_name) const {
  if (!sensor_names) return false;
  for (std::size_t k = 0; k < sensor_names->size(); ++k)
    if ((*sensor_names)[k] == sensor_name) return fired(k);
  return false;
}

void Registry::add(std::string name, Controller controller, std::string summary) {
  entries_[std::move(name)] = {std::move(controller), std::move(summary)};
}

const Controller* Registry::find(const std::string& name) const {
  auto it = entries_.find(name);
  return it == entries_.end() ? nullptr : &it->second.first;
}

const Controller& Registry::require(const std::string& name, const std::string& context) const {
  if (const Controller* c = find(name)) return *c;
  throw std::invalid_argument(context.empty() ? not_registered(name) : context + ": " + not_registered(name));
}

std::string Registry::not_registered(const std::string& name) const {
  return "controller '" + name + "' is not registered; known: " + sim::join_names(names());
}

std::vector<std::string> Registry::names() const {
  std::vector<std::string> out;
  for (const auto& [name, entry] : entries_) out.push_back(name);
  return out;
}

const std::string& Registry::summary(const std::string& name) const {
  static const std::string none;
  auto it = entries_.find(name);
  return it == entries_.end() ? none : it->second.second;
}

void script_controller(Turtle& t, const Params& p) {
  const nlohmann::json& commands = p.json().contains("commands") ? p.json().at("commands") : nlohmann::json::array();
  if (!commands.is_array()) throw std::invalid_argument("params.commands must be a list of [command, amount]");
  for (std::size_t k = 0; k < commands.size(); ++k) {
    const nlohmann::json& c = commands[k];
    const std::string where = "params.commands[" + std::to_string(k) + "]";
    if (!c.is_array() || c.empty() || !c[0].is_string())
      throw std::invalid_argument(where + " must be [command, amount], e.g. [\"forward\", 100]");
    const std::string name = c[0].get<std::string>();
    if (name == "pendown" && c.size() == 2 && c[1].is_string()) {
      const std::string mode = c[1].get<std::string>();
      if (mode != "wall" && mode != "line")
        throw std::invalid_argument(where + ": a pen mode is \"line\" or \"wall\", got \"" + mode + "\"");
      t.pen_down(mode == "wall" ? PenMode::wall : PenMode::line);
      continue;
    }
    if (name == "pendown") { t.pen_down(); continue; }
    if (name == "penup") { t.pen_up(); continue; }
    if (c.size() != 2 || !c[1].is_number())
      throw std::invalid_argument(where + ": '" + name + "' needs one number, e.g. [\"" + name + "\", 100]");
    const double amount = c[1].get<double>();
    if (name == "forward") t.forward(amount);
    else if (name == "back") t.back(amount);
    else if (name == "left") t.left(amount);
    else if (name == "right") t.right(amount);
    else if (name == "wait") t.wait(amount);
    else
      throw std::invalid_argument(where + ": unknown command '" + name +
                                  "'; known: forward, back, left, right, wait, pendown, penup");
  }
}

Registry base_registry() {
  Registry r;
  r.add("script", script_controller, "runs params.commands, a fixed list of [command, amount]");
  return r;
}

// ---------------------------------------------------------------------------------------------
// Agents: the runtime's side of each turtle

// Laid out hot first: at 10^4 turtles every resume starts with cache misses, so what the scheduler
// and a resumed program touch at each turn sits in the first few cache lines (see prefetch()).
class alignas(64) Agent {
 public:
  Agent() = default;
  Agent(const Agent&) = delete;
  Agent& operator=(const Agent&) = delete;
  // A program suspended mid-command is unwound first, while everything it may still use is alive.
  ~Agent() { fiber.reset(); }

  WorldServer::Impl* server = nullptr;
  std::size_t index = 0;
  std::optional<detail::Fiber> fiber;
  // The handshake with the scheduler.
  std::optional<sim::TurtleCommand> command;  // issued by the program, taken by the scheduler
  bool started = false;
  bool finished = false;
  bool waiting = false;    // suspended in issue(), for finish_command() to answer
  bool lays_wall = false;  // the command waited on lays a wall (the pen in wall mode, a move)
  sim::TurtleCommand::Kind waiting_on = sim::TurtleCommand::Kind::stop;
  bool pen_down = false;
  bool it = false;                            // the game's role, as Turtle::it() reports it
  PenMode pen_mode = PenMode::line;
  double odometer = 0.0;
  Result answer;                              // finish_command()'s, taken by issue() on resuming
  std::vector<Touch> inbox;                   // touches to deliver when the program resumes
  std::vector<Message> messages;              // messages to deliver when the program resumes
  std::function<void(const Touch&)> handler;
  std::function<void(const Message&)> message_handler;
  std::vector<sim::TurtleContact> in_contact;  // contacts in force (touching() makes their Touch)
  std::vector<sim::Vec2> trail;
  detail::Mt64 rng;  // uniform(); its index (first) is hot, its 2.5 KB of state is not

  // Cold: set up once, or used rarely.
  std::string id;
  TurtleProgram program;
  Controller controller;
  Params params;
  std::vector<std::string> sensor_names;      // what Touch::sensor_names points to
  std::size_t walls_laid = 0;                 // k of the next `<id>-w<k>`
  std::string fault;
  sim::Vec2 stroke_start;                     // where the wall pen's stroke began

  Result issue(sim::TurtleCommand c);
  /// The touch and message handlers, on the program's stack (they may issue commands).
  [[gnu::noinline]] void deliver();
  [[noreturn, gnu::noinline, gnu::cold]] void not_own_program() const;
  Touch make_touch(const sim::TurtleContact& c) const;
  /// Cache hint: the hot lines above (everything up to and including the generator's index).
  void prefetch() const {
    const char* p = reinterpret_cast<const char*>(this);
    const char* end = reinterpret_cast<const char*>(&rng) + sizeof(std::size_t);
    for (; p < end; p += 64) __builtin_prefetch(p);
  }
  /// Cache hint, once prefetch() has brought the index: the state word uniform() reads next.
  void prefetch_rng() const { __builtin_prefetch(rng.next_address()); }
  /// Cache hint for make_touch(), in two stages: the agent and where its sensor arcs are listed,
  /// then (once those have arrived) the arcs themselves.
  void prefetch_for_touch() const {
    prefetch();
    __builtin_prefetch(&program.sensors);
  }
  void prefetch_sensors() const { __builtin_prefetch(program.sensors.data()); }
};

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

  Impl(sim::WorldDef d, ServerOptions o) : def(std::move(d)), world(def, o.mode), options(o) {}

  double boundary_time(std::uint64_t k) const { return static_cast<double>(k) * def.dt; }
  void control_step();
  void run_program(Agent& a);
  void finish_command(Agent& a);
  void drain_sim_events();
  void lay_wall(Agent& a, sim::Vec2 from, sim::Vec2 to);
  bool id_taken(const std::string& id) const;
  void emit(LogEvent e) {
    if (log) log->push_back(std::move(e));
  }
  std::string other_id(sim::EventKind kind, std::uint32_t other) const {
    switch (kind) {
      case sim::EventKind::turtle_turtle: return def.turtles[other].id;
      case sim::EventKind::turtle_ball: return def.balls[other].id;
      default: return world.walls()[other].id;
    }
  }
  std::uint64_t sensors_for(const Agent& a, double bearing) const;

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

std::uint64_t WorldServer::Impl::sensors_for(const Agent& a, double bearing) const {
  std::uint64_t fired = 0;
  for (std::size_t k = 0; k < a.program.sensors.size(); ++k) {
    const SensorArc& s = a.program.sensors[k];
    const double span = s.to - s.from;
    if (sim::wrap_degrees(bearing - s.from) < (span >= 360.0 ? 360.0 : sim::wrap_degrees(span))) fired |= std::uint64_t{1} << k;
  }
  return fired;
}

Touch Agent::make_touch(const sim::TurtleContact& c) const {
  // The contact point lies against the normal (which points from the obstacle to the turtle).
  const sim::Vec2 d = -c.normal;
  const double heading_deg = sim::api_degrees(server->world.turtle(index).heading);
  Touch t;
  t.bearing = sim::wrap_degrees(sim::api_degrees(sim::heading_of(d)) - heading_deg);
  t.sensors = server->sensors_for(*this, t.bearing);
  t.sensor_names = &sensor_names;
  t.what = server->other_id(c.kind, c.other);
  t.kind = kind_word(c.kind);
  t.t = c.t;
  return t;
}

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

void WorldServer::Impl::finish_command(Agent& a) {
  // The end of the command the program waits on, worked out before it resumes (see issue()).
  a.waiting = false;
  const sim::TurtleState s = world.turtle(a.index);
  if (a.waiting_on == sim::TurtleCommand::Kind::move) a.odometer += s.done;
  if (a.pen_down) a.trail.push_back(s.pos);
  if (a.lays_wall && s.pos != a.stroke_start) lay_wall(a, a.stroke_start, s.pos);
  const double done = a.waiting_on == sim::TurtleCommand::Kind::turn ? sim::api_degrees(s.done) : s.done;
  // A touch that cut the command short is the first of those delivered on resuming.
  a.answer = s.touched && !a.inbox.empty() ? Result(done, a.inbox.front()) : Result(done, std::nullopt);
}

// ---------------------------------------------------------------------------------------------
// The controller API

Result Turtle::forward(double distance) { return agent_->issue({sim::TurtleCommand::Kind::move, distance}); }
Result Turtle::back(double distance) { return agent_->issue({sim::TurtleCommand::Kind::move, -distance}); }
Result Turtle::right(double degrees) { return agent_->issue({sim::TurtleCommand::Kind::turn, sim::to_radians(degrees)}); }
Result Turtle::left(double degrees) { return agent_->issue({sim::TurtleCommand::Kind::turn, sim::to_radians(-degrees)}); }
Result Turtle::wait(double seconds) { return agent_->issue({sim::TurtleCommand::Kind::wait, seconds}); }
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
double Turtle::heading() const { return sim::wrap_degrees(sim::api_degrees(agent_->server->world.turtle(agent_->index).heading)); }
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
  const double heading_deg = sim::api_degrees(agent_->server->world.turtle(agent_->index).heading);
  for (const sim::TurtleContact& c : agent_->in_contact) {
    Touch t;
    const sim::Vec2 d = -c.normal;
    t.bearing = sim::wrap_degrees(sim::api_degrees(sim::heading_of(d)) - heading_deg);
    t.sensors = agent_->server->sensors_for(*agent_, t.bearing);
    t.sensor_names = &agent_->sensor_names;
    t.what = agent_->server->other_id(c.kind, c.other);
    t.kind = kind_word(c.kind);
    t.t = c.t;
    out.push_back(std::move(t));
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Wall-laying turtles

sim::WorldDef with_builder_layers(sim::WorldDef def, const std::vector<TurtleProgram>& programs) {
  std::uint32_t used = 0;
  for (const auto& w : def.walls) used |= w.layers.category;
  for (const auto& b : def.balls) used |= b.layers.category;
  for (const auto& t : def.turtles) used |= t.layers.category;
  const std::size_t n = std::min(programs.size(), def.turtles.size());
  for (std::size_t k = 0; k < n; ++k) {
    if (!programs[k].builder) continue;
    // Free bits from the top down, away from the world file's named categories (bit 0 upwards).
    int bit = 31;
    while (bit >= 0 && ((used >> bit) & 1u) != 0) --bit;
    if (bit < 0)
      throw std::invalid_argument("turtle '" + def.turtles[k].id +
                                  "' lays walls but no collision category is free for it (32 in use); use fewer "
                                  "category names or fewer builder turtles");
    const std::uint32_t own = std::uint32_t{1} << bit;
    used |= own;
    sim::TurtleDef& builder = def.turtles[k];
    // Whoever collided with the builder's categories collides with its private one too, so moving
    // it there changes nothing but its own walls (whose mask leaves `own` out).
    const std::uint32_t was = builder.layers.category;
    auto widen = [&](sim::Layers& l) {
      if ((l.mask & was) != 0) l.mask |= own;
    };
    for (auto& w : def.walls) widen(w.layers);
    for (auto& b : def.balls) widen(b.layers);
    for (std::size_t j = 0; j < def.turtles.size(); ++j)
      if (j != k) widen(def.turtles[j].layers);
    builder.layers.category = own;
  }
  return def;
}

bool WorldServer::Impl::id_taken(const std::string& id) const {
  for (const auto& w : world.walls())
    if (w.id == id) return true;
  for (const auto& b : def.balls)
    if (b.id == id) return true;
  for (const auto& t : def.turtles)
    if (t.id == id) return true;
  return false;
}

void WorldServer::Impl::lay_wall(Agent& a, sim::Vec2 from, sim::Vec2 to) {
  const double now = world.time();
  sim::WallDef w;
  do w.id = a.id + "-w" + std::to_string(a.walls_laid++);
  while (id_taken(w.id));
  w.from = from;
  w.to = to;
  // In the default category, colliding with everything except the builder's private category.
  w.layers.category = 1;
  w.layers.mask = ~def.turtles[a.index].layers.category;
  try {
    world.add_wall(w);
  } catch (const std::invalid_argument& e) {
    spdlog::warn("turtle '{}' t={:.6g}: wall {} not laid: {}", a.id, now, w.id, e.what());
    emit({now, "wall-refused", a.id, w.id, {}, 0.0, e.what()});
    return;
  }
  emit({now, "wall-drawn", a.id, w.id, {}, 0.0, {}});
}

// ---------------------------------------------------------------------------------------------
// The scheduler

WorldServer::WorldServer(const sim::WorldDef& def, std::vector<TurtleProgram> programs, const Registry& registry,
                         ServerOptions options)
    : impl_(std::make_unique<Impl>(with_builder_layers(def, programs), options)) {
  if (programs.size() != def.turtles.size())
    throw std::invalid_argument("WorldServer: " + std::to_string(programs.size()) + " programs for " +
                                std::to_string(def.turtles.size()) + " turtles");
  for (std::size_t k = 0; k < programs.size(); ++k) {
    auto a = std::make_unique<Agent>();
    a->server = impl_.get();
    a->index = k;
    a->id = def.turtles[k].id;
    a->program = std::move(programs[k]);
    const Controller& controller = registry.require(a->program.controller, "turtle '" + a->id + "'");
    if (a->program.sensors.empty() || a->program.sensors.size() > 64)
      throw std::invalid_argument("turtle '" + a->id + "' needs 1 to 64 sensors (has " +
                                  std::to_string(a->program.sensors.size()) + ")");
    for (const SensorArc& arc : a->program.sensors) a->sensor_names.push_back(arc.name);
    a->controller = controller;
    a->params = Params(a->program.params);
    a->pen_down = a->program.pen_down || a->program.pen_walls;
    if (a->program.pen_walls) {
      if (!a->program.builder)
        throw std::invalid_argument("turtle '" + a->id + "': its pen starts in wall mode but it is not a builder");
      a->pen_mode = PenMode::wall;
    }
    if (a->pen_down) a->trail.push_back(def.turtles[k].pos);
    a->rng.seed_with(def.seed ^ fnv1a(a->id));
    impl_->agents.push_back(std::move(a));
  }
  impl_->world.set_event_log(&impl_->sim_log);
}

WorldServer::~WorldServer() = default;

void WorldServer::Impl::run_program(Agent& a) {
  if (!a.started) {
    a.started = true;
    Agent* agent = &a;
    a.fiber.emplace(
        [agent] {
          Turtle t(*agent);
          agent->controller(t, agent->params);
        },
        options.stack_bytes);
  }
  if (a.waiting) finish_command(a);
  const auto outcome = a.fiber->resume(options.program_budget);
  const double now = world.time();
  auto park = [&](const std::string& fault) {
    a.finished = true;
    a.fault = fault;
    world.command_turtle(a.index, {sim::TurtleCommand::Kind::stop, 0.0});
    if (!fault.empty()) {
      spdlog::error("turtle '{}' stopped at t={:.6g}: {}", a.id, now, fault);
      emit({now, "fault", a.id, {}, {}, 0.0, fault});
    }
  };
  switch (outcome) {
    case detail::Fiber::Outcome::suspended:
      if (a.command) {
        world.command_turtle(a.index, *a.command);
        if (a.command->kind == sim::TurtleCommand::Kind::move && a.command->amount != 0.0) a.in_contact.clear();
        a.command.reset();
      }
      return;
    case detail::Fiber::Outcome::finished:
      if (auto err = a.fiber->error()) {
        std::string what = "its program threw a non-standard exception";
        try {
          std::rethrow_exception(err);
        } catch (const std::exception& e) {
          what = std::string("its program threw: ") + e.what();
        } catch (...) {
        }
        park(what);
      } else {
        park({});  // the program returned: the turtle stays parked where it is
      }
      return;
    case detail::Fiber::Outcome::stack_overflow:
      park("its program overflowed its stack (" + std::to_string(options.stack_bytes / 1024) +
           " KiB); deep recursion or large locals? raise the stack size with --stack-kib");
      return;
    case detail::Fiber::Outcome::over_budget:
      a.finished = true;
      a.fault = "busy loop";
      throw BusyLoopError("turtle '" + a.id + "': its program ran for more than " +
                          std::to_string(options.program_budget) +
                          " s of wall time without issuing a command (a busy loop?); the run stops at t=" +
                          std::to_string(now));
  }
}

void WorldServer::Impl::control_step() {
  // 1. Contacts of the previous step become interrupts.
  const double now = world.time();
  const std::vector<sim::TurtleContact> contacts = world.take_turtle_contacts();
  // Contacts come in time order, so each starts with cache misses on its agent, the agent's
  // sensor arcs and the other body's id: asked for one and two contacts ahead.
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    if (k + 2 < contacts.size()) agents[contacts[k + 2].turtle]->prefetch_for_touch();
    if (k + 1 < contacts.size()) {
      const sim::TurtleContact& next = contacts[k + 1];
      agents[next.turtle]->prefetch_sensors();
      if (next.kind == sim::EventKind::turtle_turtle) __builtin_prefetch(&def.turtles[next.other].id);
      else if (next.kind == sim::EventKind::turtle_ball) __builtin_prefetch(&def.balls[next.other].id);
    }
    const sim::TurtleContact& c = contacts[k];
    Agent& a = *agents[c.turtle];
    Touch t = a.make_touch(c);
    if (log) {
      LogEvent e{now, "touch", a.id, t.what, {}, t.bearing, {}};
      for (std::size_t s = 0; s < a.program.sensors.size(); ++s)
        if (t.fired(s)) e.sensors.push_back(a.program.sensors[s].name);
      emit(std::move(e));
    }
    a.in_contact.push_back(c);
    if (!a.finished) a.inbox.push_back(std::move(t));
  }
  // 1a. The game's referee, on the same contacts.
  if (game) game->referee(now, contacts, *this);
  // 2. Programs, in world-file order, each until its next command. A turtle whose command is
  //    still running is left alone; the engine lists the others in one pass. (Running one program
  //    commands only its own turtle, so the list made up front is the one a check turtle by turtle
  //    would give.) A resume after a long while misses the cache on the agent, its fiber's record
  //    and its stack, each found through the one before: they are asked for a few turns ahead.
  idle.clear();
  world.idle_turtles(idle);
  const std::size_t n = idle.size();
  for (std::size_t k = 0; k < n; ++k) {
    if (k + 3 < n) agents[idle[k + 3]]->prefetch();
    if (k + 2 < n) {
      const Agent& b = *agents[idle[k + 2]];
      if (b.fiber) b.fiber->prefetch_record();
      world.prefetch_turtle(idle[k + 2]);  // for finish_command() and the command that follows
    }
    if (k + 1 < n) {
      const Agent& b = *agents[idle[k + 1]];
      if (b.fiber) b.fiber->prefetch_stack();
      b.prefetch_rng();
    }
    Agent& a = *agents[idle[k]];
    if (a.finished) continue;
    run_program(a);
  }
}

void WorldServer::Impl::drain_sim_events() {
  if (log)
    for (const sim::Event& e : sim_log) {
      LogEvent out{e.t, std::string(sim::to_string(e.kind)), {}, {}, {}, 0.0, {}};
      switch (e.kind) {
        case sim::EventKind::ball_ball:
          out.a = def.balls[e.a].id;
          out.b = def.balls[e.b].id;
          break;
        case sim::EventKind::ball_wall:
        case sim::EventKind::ball_wall_end:
          out.a = def.balls[e.a].id;
          out.b = world.walls()[e.b].id;
          break;
        case sim::EventKind::exit: out.a = e.b == 1 ? def.turtles[e.a].id : def.balls[e.a].id; break;
        default:
          out.a = def.turtles[e.a].id;
          out.b = other_id(e.kind, e.b);
      }
      emit(std::move(out));
    }
  sim_log.clear();
}

void WorldServer::run_until(double t) {
  Impl& s = *impl_;
  for (;;) {
    if (!s.boundary_done) {
      s.control_step();
      s.boundary_done = true;
    }
    const double next = s.boundary_time(s.step + 1);
    if (next <= t) {
      s.world.advance_to(next);
      s.drain_sim_events();
      ++s.step;
      s.boundary_done = false;
      continue;
    }
    if (t > s.world.time()) s.world.advance_to(t);
    s.drain_sim_events();
    return;
  }
}

double WorldServer::time() const { return impl_->world.time(); }
const sim::World& WorldServer::world() const { return impl_->world; }
void WorldServer::set_event_log(std::vector<LogEvent>* log) { impl_->log = log; }
void WorldServer::set_game(std::unique_ptr<Game> game) {
  impl_->game = std::move(game);
  for (auto& a : impl_->agents) a->it = false;
  if (impl_->game) impl_->game->start(impl_->world.time(), *impl_);
}
const Game* WorldServer::game() const { return impl_->game.get(); }
std::size_t WorldServer::turtle_count() const { return impl_->agents.size(); }

WorldServer::TurtleInfo WorldServer::turtle(std::size_t i) const {
  const Agent& a = *impl_->agents[i];
  TurtleInfo info{a.id, impl_->world.turtle(i), a.pen_down, a.finished, a.fault, a.trail};
  if (a.pen_down) info.trail.push_back(info.state.pos);
  return info;
}

std::size_t WorldServer::stack_reservation() const {
  for (const auto& a : impl_->agents)
    if (a->fiber) return a->fiber->reserved_bytes();
  return 0;
}

}  // namespace turtlegas::turtle
