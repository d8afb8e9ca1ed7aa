// SPDX-License-Identifier: MIT
// The runtime's side of one turtle: its program's fiber, the handshake of a command with the
// scheduler, what waits to be delivered (touches, messages), the pen and the odometer. The Turtle
// API's bodies (agent.cpp) work on it; the scheduler (world_server.cpp) drives it.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fiber.hpp"
#include "mt64.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/turtle/remote.hpp"
#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::turtle {

// Laid out hot first: at 10^4 turtles every resume starts with cache misses, so what the scheduler
// and a resumed program touch at each turn sits in the first few cache lines (see prefetch()).
class alignas(64) Agent {
 public:
  Agent() = default;
  Agent(const Agent&) = delete;
  Agent& operator=(const Agent&) = delete;
  // A program suspended mid-command is unwound first, while everything it may still use is alive
  // (end_program, agent.cpp).
  ~Agent() { end_program(); }

  WorldServer::Impl* server = nullptr;
  std::size_t index = 0;
  std::optional<detail::Fiber> fiber;
  // The handshake with the scheduler.
  std::optional<sim::TurtleCommand> command;  // issued by the program, taken by the scheduler
  bool started = false;
  bool finished = false;
  bool waiting = false;    // suspended in issue(), for finish_command() to answer
  bool lays_wall = false;  // the command waited on lays a wall (the pen in wall mode, a move)
  bool remote = false;       // runs the remote program (remote.hpp, remote.cpp)
  bool wants_input = false;  // the remote program is suspended in await_remote()
  bool ending = false;     // end_program() is unwinding the program: a command now abandons it
  bool gone = false;       // the turtle has left the world: every command throws TurtleGone
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
  sim::Vec2 stroke_start;                     // where the wall pen's stroke (or a pen's arc) began
  double stroke_heading = 0.0;                // an arc's heading at its start, radians
  sim::TurtleCommand stroke;                  // the arc a lowered pen follows (pen_chords.hpp)
  std::optional<RemoteCommand> remote_input;  // the InputSource's command, for await_remote()

  Result issue(sim::TurtleCommand c);
  /// The remote program's wait for its next command (remote.cpp): suspends until the scheduler
  /// has one, delivering touches and messages that arrive meanwhile.
  RemoteCommand await_remote();
  /// Unwinds a program suspended mid-command (Fiber::stop); one that will not be unwound (it
  /// catches the unwinding and issues a command, or loops) is abandoned with a warning naming the
  /// turtle.
  void end_program();
  /// issue() while end_program() unwinds: warns and leaves the program for good.
  [[noreturn, gnu::noinline, gnu::cold]] void refuse_while_ending(sim::TurtleCommand c);
  /// The touch and message handlers, on the program's stack (they may issue commands).
  [[gnu::noinline]] void deliver();
  [[noreturn, gnu::noinline, gnu::cold]] void not_own_program() const;
  /// Tells the program its turtle has left the world (TurtleGone).
  [[noreturn, gnu::noinline, gnu::cold]] void throw_gone() const;
  /// Reads range sensor `name` now into out (senses.cpp); `mirrored`: each ray at bearing b looks
  /// along 360 - b (a mirrored handle's view); `camera_only`: throws unless it is a camera
  /// (Turtle::camera). A camera's readings carry colours. Logs the `sense` event.
  void sense(const std::string& name, bool mirrored, std::vector<Reading>& out, bool camera_only = false);
  /// Contact c as this turtle's program sees it now (server_impl.hpp).
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

namespace detail {
/// The remote program (remote.cpp), bound to agent a: what a remote turtle's fiber runs.
Controller remote_program_for(Agent& a);
}  // namespace detail

}  // namespace turtlegas::turtle
