// SPDX-License-Identifier: MIT
// The scheduler: the control step of world_server.hpp (interrupts, the game's referee, programs in
// world-file order), a program's turn on its fiber, the end of a command, and running to a time.
#include "turtlegas/turtle/world_server.hpp"

#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <spdlog/spdlog.h>

#include "agent.hpp"
#include "fiber.hpp"
#include "mirror_controller.hpp"
#include "server_impl.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/turtle/event_names.hpp"
#include "turtlegas/turtle/game.hpp"
#include "turtlegas/turtle/remote.hpp"

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

ProgramInFlight g_in_flight;

/// Marks a's program as the one running for the span of a resume.
class InFlight {
 public:
  InFlight(const Agent& a, double t) {
    g_in_flight.t = t;
    g_in_flight.controller = a.program.controller.c_str();
    g_in_flight.turtle = a.id.c_str();
  }
  ~InFlight() {
    g_in_flight.turtle = nullptr;
    g_in_flight.controller = nullptr;
  }
  InFlight(const InFlight&) = delete;
  InFlight& operator=(const InFlight&) = delete;
};

std::atomic<void (*)()> g_busy_loop_last_words{nullptr};

/// A line a signal handler may build: a fixed buffer, no allocation, write(2) only.
class SafeLine {
 public:
  SafeLine& operator<<(const char* s) {
    while (s != nullptr && *s != '\0' && n_ < sizeof buf_) buf_[n_++] = *s++;
    return *this;
  }
  /// Up to three decimals, trailing zeros dropped (no C library: printf is not signal-safe).
  SafeLine& operator<<(double v) {
    if (!(v >= 0.0 && v < 1e15)) return *this << (v < 0.0 ? "(negative)" : "(huge)");
    auto milli = static_cast<std::uint64_t>(v * 1000.0 + 0.5);
    char digits[24];
    int n = 0;
    do digits[n++] = static_cast<char>('0' + milli % 10), milli /= 10;
    while (milli > 0 || n < 4);
    int low = 0;  // trailing zeros of the decimals go
    while (low < 3 && digits[low] == '0') ++low;
    for (int k = n - 1; k >= 3; --k) put(digits[k]);
    if (low < 3) put('.');
    for (int k = 2; k >= low; --k) put(digits[k]);
    return *this;
  }
  void write() const { [[maybe_unused]] const ssize_t r = ::write(STDERR_FILENO, buf_, n_); }

 private:
  void put(char c) {
    if (n_ < sizeof buf_) buf_[n_++] = c;
  }
  char buf_[1024];
  std::size_t n_ = 0;
};

/// The end of a busy loop that calls no Turtle API (fiber.hpp): from SIGALRM's handler.
[[noreturn]] void busy_loop_exit(double budget) {
  const ProgramInFlight& p = g_in_flight;
  SafeLine line;
  line << "turtlegas: ";
  if (p.turtle != nullptr)
    line << "turtle '" << p.turtle << "' (controller '" << (p.controller ? p.controller : "?") << "'): ";
  line << "its program ran for more than " << budget << " s of wall time without issuing a command, and "
       << budget << " s more without calling the Turtle API (a busy loop?); it cannot be stopped safely where it "
       << "runs, so the process stops at t=" << static_cast<double>(p.t) << "\n";
  line.write();
  if (void (*last_words)() = g_busy_loop_last_words.load(std::memory_order_relaxed)) last_words();
  ::_exit(1);
}

}  // namespace

const ProgramInFlight& program_in_flight() { return g_in_flight; }

void set_busy_loop_last_words(void (*last_words)()) {
  g_busy_loop_last_words.store(last_words, std::memory_order_relaxed);
}

void WorldServer::Impl::finish_command(Agent& a) {
  // The end of the command the program waits on, worked out before it resumes (see issue()).
  a.waiting = false;
  // A turtle that has left the world (crushed, out of an open arena) hears of it from the command
  // it waited in (TurtleGone, issue()).
  if (!world.turtle_alive(a.index)) [[unlikely]] {
    a.gone = true;
    a.inbox.clear();
    return;
  }
  const sim::TurtleState s = world.turtle(a.index);
  const bool arc = a.waiting_on == sim::TurtleCommand::Kind::arc;
  if (a.waiting_on == sim::TurtleCommand::Kind::move || arc) a.odometer += s.done;  // an arc's: along it
  // (An arc's length, not where it ended: a whole lap ends exactly where it began.)
  if (arc && (a.pen_down || a.lays_wall) && s.done != 0.0) [[unlikely]] {
    pen_arc(a, s);
  } else {
    if (a.pen_down) a.trail.push_back(s.pos);
    if (a.lays_wall && s.pos != a.stroke_start) lay_wall(a, a.stroke_start, s.pos);
  }
  const double done = a.waiting_on == sim::TurtleCommand::Kind::turn ? sim::to_degrees(s.done) : s.done;
  // A touch that cut the command short is the first of those delivered on resuming.
  a.answer = s.touched && !a.inbox.empty() ? Result(done, a.inbox.front()) : Result(done, std::nullopt);
}

std::unique_ptr<Agent> WorldServer::Impl::make_agent(std::size_t k, TurtleProgram program,
                                                    const std::vector<std::string>& turtle_ids) {
  const Registry& reg = registry;
  auto a = std::make_unique<Agent>();
  a->server = this;
  a->index = k;
  a->id = def.turtles[k].id;
  a->program = std::move(program);
  a->remote = a->program.controller == remote_controller_name;  // the runtime's own program (remote.cpp)
  const Controller* controller = a->remote ? nullptr : reg.find(a->program.controller);
  if (!controller && !a->remote)  // Registry::require's message; its context built only when it is needed
    throw std::invalid_argument("turtle '" + a->id + "': " + reg.not_registered(a->program.controller));
  Controller composed;  // a mirror: the controller it mirrors, through Turtle::mirrored
  if (a->program.controller == "mirror") {
    composed = detail::compose_mirror(reg, a->program.params, a->id, turtle_ids);
    controller = &composed;
  }
  if (a->program.sensors.empty() || a->program.sensors.size() > 64)
    throw std::invalid_argument("turtle '" + a->id + "' needs 1 to 64 sensors (has " +
                                std::to_string(a->program.sensors.size()) + ")");
  for (const SensorArc& arc : a->program.sensors) a->sensor_names.push_back(arc.name);
  a->controller = a->remote ? detail::remote_program_for(*a) : *controller;
  // The declared defaults are the controller's (Params::get<T>(key)); the loader has checked
  // the rest against the declarations. A remote turtle's params are its client's business.
  a->params = a->remote ? Params(a->program.params)
                        : Params(with_defaults(*reg.info(a->program.controller), a->program.params));
  a->pen_down = a->program.pen_down || a->program.pen_walls;
  if (a->program.pen_walls) {
    if (!a->program.builder)
      throw std::invalid_argument("turtle '" + a->id + "': its pen starts in wall mode but it is not a builder");
    a->pen_mode = PenMode::wall;
  }
  if (a->pen_down) a->trail.push_back(def.turtles[k].pos);
  // Its own stream, or (a mirror with a twin) the twin's, so that a randomised program has an
  // exact mirror image.
  a->rng.seed_with(def.seed ^ fnv1a(detail::stream_owner(a->program.controller, a->program.params, a->id)));
  return a;
}

WorldServer::WorldServer(const sim::WorldDef& def, std::vector<TurtleProgram> programs, const Registry& registry,
                         ServerOptions options)
    : impl_(std::make_unique<Impl>(with_builder_layers(def, programs), std::move(options))) {
  if (programs.size() != def.turtles.size())
    throw std::invalid_argument("WorldServer: " + std::to_string(programs.size()) + " programs for " +
                                std::to_string(def.turtles.size()) + " turtles");
  impl_->registry = registry;
  std::vector<std::string> ids;
  for (const auto& t : def.turtles) ids.push_back(t.id);
  for (std::size_t k = 0; k < programs.size(); ++k)
    impl_->agents.push_back(impl_->make_agent(k, std::move(programs[k]), ids));
  impl_->world.set_event_log(&impl_->sim_log);
  impl_->self = this;
  detail::set_busy_loop_exit(&busy_loop_exit);
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
  // A remote program waiting for its next command is resumed only when there is something for it
  // (remote.cpp); it may take several turns at one boundary (its touches first, pen commands).
  if (a.wants_input && !feed_remote(a)) [[unlikely]] return;
  while (resume(a)) {
  }
}

bool WorldServer::Impl::resume(Agent& a) {
  const double now = world.time();
  detail::Fiber::Outcome outcome;
  {
    const InFlight in_flight(a, now);
    outcome = a.fiber->resume(options.program_budget);
  }
  auto park = [&](const std::string& fault) {
    a.finished = true;
    a.fault = fault;
    world.command_turtle(a.index, {sim::TurtleCommand::Kind::stop, 0.0});
    if (!fault.empty()) {
      spdlog::error("turtle '{}' stopped at t={:.6g}: {}", a.id, now, fault);
      emit({now, "fault", a.id, {}, {}, 0.0, fault, {}, {}});
      if (a.remote) [[unlikely]] {
        RemoteReport r = report_of(a, RemoteReport::Kind::fault);
        r.fault = fault;
        reports.push_back(std::move(r));
      }
    }
  };
  switch (outcome) {
    case detail::Fiber::Outcome::suspended:
      if (a.command) {
        if (a.command->kind == sim::TurtleCommand::Kind::arc) [[unlikely]] {
          // The engine refuses an arc where a wall turns or stretches (no exact solver): a fault
          // of this turtle's program, as if its call had thrown, not the end of the run.
          try {
            world.command_turtle(a.index, *a.command);
          } catch (const std::invalid_argument& e) {
            a.command.reset();
            a.waiting = false;
            park(std::string("its arc was refused: ") + e.what());
            return false;
          }
        } else {
          world.command_turtle(a.index, *a.command);
        }
        // A turtle that drives away leaves its contacts (one turning on the spot keeps them).
        const sim::TurtleCommand& c = *a.command;
        if ((c.kind == sim::TurtleCommand::Kind::move && c.amount != 0.0) ||
            (c.kind == sim::TurtleCommand::Kind::arc && c.amount > 0.0 && c.speed != 0.0))
          a.in_contact.clear();
        a.command.reset();
        return false;
      }
      return a.wants_input && feed_remote(a);  // a remote program that took its touches, or ran a pen command
    case detail::Fiber::Outcome::finished:
      if (auto err = a.fiber->error()) {
        std::string what = "its program threw a non-standard exception";
        try {
          std::rethrow_exception(err);
        } catch (const TurtleGone&) {
          park({});  // the turtle is gone, and its program with it: not a fault
          return false;
        } catch (const std::exception& e) {
          what = std::string("its program threw: ") + e.what();
        } catch (...) {
        }
        park(what);
      } else {
        park({});  // the program returned: the turtle stays parked where it is
      }
      return false;
    case detail::Fiber::Outcome::stack_overflow:
      park("its program overflowed its stack (" + std::to_string(options.stack_bytes / 1024) +
           " KiB); deep recursion or large locals? raise the stack size with --stack-kib");
      return false;
    case detail::Fiber::Outcome::over_budget:
      a.finished = true;
      a.fault = "busy loop";
      throw BusyLoopError("turtle '" + a.id + "': its program ran for more than " +
                          std::to_string(options.program_budget) +
                          " s of wall time without issuing a command (a busy loop?); the run stops at t=" +
                          std::to_string(now));
  }
  return false;
}

void WorldServer::Impl::control_step() {
  // 0. The host's changes to the world, at this boundary.
  if (options.input) options.input->at_boundary(*self, step);
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
    // A turtle crushed at its contact (or gone since) has no sensors left to fire.
    if (!world.turtle_alive(c.turtle)) [[unlikely]] continue;
    Touch t = a.make_touch(c);
    if (log) {
      LogEvent e{now, "touch", a.id, t.what, {}, t.bearing, {}, {}, {}};
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
  flush_reports();
}

void WorldServer::Impl::drain_sim_events() {
  if (log)
    for (const sim::Event& e : sim_log) {
      const EventIds ids = name_event(e, names());
      emit({e.t, std::string(sim::to_string(e.kind)), std::string(ids.a), ids.b ? std::string(*ids.b) : std::string(),
            {}, 0.0, {}, ids.c ? std::string(*ids.c) : std::string(), {}});
    }
  sim_log.clear();
}

void WorldServer::run_until(double t) {
  Impl& s = *impl_;
  // An engine stopped inside a step (an event limit, a stop poll) has logged up to its last event:
  // that much reaches the log too.
  auto advance = [&s](double to) {
    try {
      s.world.advance_to(to);
    } catch (const sim::EventLimitReached&) {
      s.drain_sim_events();
      throw;
    } catch (const sim::StopRequested&) {
      s.drain_sim_events();
      throw;
    }
  };
  for (;;) {
    if (!s.boundary_done) {
      s.control_step();
      s.boundary_done = true;
    }
    const double next = s.boundary_time(s.step + 1);
    if (next <= t) {
      advance(next);
      s.drain_sim_events();
      ++s.step;
      s.boundary_done = false;
      continue;
    }
    if (t > s.world.time()) advance(t);
    s.drain_sim_events();
    return;
  }
}

void WorldServer::set_event_limit(std::uint64_t limit) { impl_->world.set_event_limit(limit); }
void WorldServer::set_stop_poll(std::function<bool()> poll, std::uint64_t every) {
  impl_->world.set_stop_poll(std::move(poll), every);
}

double WorldServer::time() const { return impl_->world.time(); }
std::uint64_t WorldServer::step() const { return impl_->step; }
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
  TurtleInfo info = turtle_status(i);
  info.trail = impl_->agents[i]->trail;
  if (info.pen_down) info.trail.push_back(info.state.pos);
  return info;
}

WorldServer::TurtleInfo WorldServer::turtle_status(std::size_t i) const {
  const Agent& a = *impl_->agents.at(i);
  TurtleInfo info{a.id, impl_->world.turtle(i), a.pen_down, a.finished, a.fault, {}};
  info.pen_mode = a.pen_mode;
  info.it = a.it;
  info.remote = a.remote;
  info.gone = !impl_->world.turtle_alive(i);
  return info;
}

std::vector<sim::Vec2> WorldServer::trail_since(std::size_t i, std::size_t from) const {
  const std::vector<sim::Vec2>& trail = impl_->agents.at(i)->trail;
  if (from >= trail.size()) return {};
  return {trail.begin() + static_cast<std::ptrdiff_t>(from), trail.end()};
}

std::size_t WorldServer::trail_size(std::size_t i) const { return impl_->agents.at(i)->trail.size(); }
const std::string& WorldServer::controller(std::size_t i) const { return impl_->agents.at(i)->program.controller; }

std::size_t WorldServer::stack_reservation() const {
  for (const auto& a : impl_->agents)
    if (a->fiber) return a->fiber->reserved_bytes();
  return 0;
}

}  // namespace turtlegas::turtle
