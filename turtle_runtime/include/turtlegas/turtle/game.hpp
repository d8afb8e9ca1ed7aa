// SPDX-License-Identifier: MIT
// A game played by the turtles of a world: a referee that the world server consults at each
// control step (see world_server.hpp for where in the step). The tag game (tag_game.hpp) is one.
#pragma once

#include <cstddef>
#include <span>
#include <string>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/world.hpp"
#include "turtlegas/turtle/log_event.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::turtle {

/// What the world server lets a game do. Valid only during the Game call it is passed to.
class GameHost {
 public:
  virtual ~GameHost() = default;
  virtual std::size_t turtle_count() const = 0;
  /// Turtle i's id from the world file (turtles are indexed in world-file order).
  virtual const std::string& turtle_id(std::size_t i) const = 0;
  /// Queues a message for turtle i's program; it is delivered when the program next resumes, after
  /// its touches (a turtle whose program has ended gets nothing).
  virtual void send(std::size_t i, Message message) = 0;
  /// Sets what turtle i's Turtle::it() reports.
  virtual void set_it(std::size_t i, bool it) = 0;
  /// Appends an event to the run's log (when one is kept).
  virtual void log_event(LogEvent event) = 0;
};

/// A referee. The server owns it (WorldServer::set_game) and calls it on its own thread.
class Game {
 public:
  virtual ~Game() = default;
  /// Called once, by WorldServer::set_game, at the server's current time t (seconds).
  virtual void start(double t, GameHost& host) = 0;
  /// Called at each control-step boundary t, with the turtles' contacts of the previous step in
  /// time order (each turtle-turtle contact appears twice, once for each turtle), after the
  /// contacts have become touch interrupts and before any program runs.
  virtual void referee(double t, std::span<const sim::TurtleContact> contacts, GameHost& host) = 0;
  /// The score so far, at time t (>= the last referee call), as JSON.
  virtual nlohmann::json score(double t) const = 0;
  /// The rules, as the players may read them (Turtle::game_rules()): a JSON object with "kind".
  virtual nlohmann::json rules_for_players() const { return nlohmann::json::object(); }
};

}  // namespace turtlegas::turtle
