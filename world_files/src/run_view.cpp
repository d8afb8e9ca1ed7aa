// SPDX-License-Identifier: MIT
#include "turtlegas/world/run_view.hpp"

#include "turtlegas/sim/angles.hpp"

namespace turtlegas::world {

RunView::RunView(const turtle::WorldServer& server, const sim::WorldDef& def) : server_(server), def_(def) {}

RunView::Body RunView::body(const std::string& id) const {
  Body b;
  const sim::World& w = world();
  for (std::size_t i = 0; i < def_.turtles.size(); ++i)
    if (def_.turtles[i].id == id) {
      const sim::TurtleState s = w.turtle(i);
      return {true, true, true, s.pos, s.vel, sim::wrap_degrees(sim::to_degrees(s.heading))};
    }
  for (std::size_t i = 0; i < def_.balls.size(); ++i)
    if (def_.balls[i].id == id) {
      const sim::BallState s = w.ball(i);
      return {true, false, s.alive, s.pos, s.vel, 0.0};
    }
  return b;
}

}  // namespace turtlegas::world
