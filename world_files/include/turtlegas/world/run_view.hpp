// SPDX-License-Identifier: MIT
// What an `expect` check sees of a run in progress (expect.hpp's Check; scenario.hpp runs them).
#pragma once

#include <cstddef>
#include <string>

#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::world {

/// What a check sees of a run in progress: the server (and through it the engine) and the scene's
/// bodies by id. Valid only during run_expectations.
class RunView {
 public:
  RunView(const turtle::WorldServer& server, const sim::WorldDef& def);

  double time() const { return server_.time(); }
  const turtle::WorldServer& server() const { return server_; }
  const sim::World& world() const { return server_.world(); }
  const sim::WorldDef& def() const { return def_; }

  /// A body by id: a ball (alive or not) or a turtle. `heading` in degrees [0, 360), turtles only.
  struct Body {
    bool found = false;
    bool turtle = false;
    bool alive = true;
    sim::Vec2 pos;
    sim::Vec2 vel;
    double heading = 0.0;
  };
  Body body(const std::string& id) const;
  /// Every ball (alive) and turtle, as (id, position).
  template <class F>
  void for_each_body(F&& f) const {
    const sim::World& w = world();
    for (std::size_t i = 0; i < w.ball_count(); ++i) {
      const sim::BallState b = w.ball(i);
      if (b.alive) f(def_.balls[i].id, b.pos);
    }
    for (std::size_t i = 0; i < w.turtle_count(); ++i) f(def_.turtles[i].id, w.turtle(i).pos);
  }

 private:
  const turtle::WorldServer& server_;
  const sim::WorldDef& def_;
};

}  // namespace turtlegas::world
