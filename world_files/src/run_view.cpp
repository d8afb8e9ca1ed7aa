// SPDX-License-Identifier: MIT
#include "turtlegas/world/run_view.hpp"

#include <cmath>
#include <numbers>

namespace turtlegas::world {

RunView::RunView(const turtle::WorldServer& server, const sim::WorldDef& def) : server_(server), def_(def) {}

RunView::Body RunView::body(const std::string& id) const {
  Body b;
  const sim::World& w = world();
  for (std::size_t i = 0; i < def_.turtles.size(); ++i)
    if (def_.turtles[i].id == id) {
      const sim::TurtleState s = w.turtle(i);
      double h = std::fmod(s.heading * (180.0 / std::numbers::pi), 360.0);
      if (h < 0.0) h += 360.0;
      if (h >= 360.0) h = 0.0;
      return {true, true, true, s.pos, s.vel, h};
    }
  for (std::size_t i = 0; i < def_.balls.size(); ++i)
    if (def_.balls[i].id == id) {
      const sim::BallState s = w.ball(i);
      return {true, false, s.alive, s.pos, s.vel, 0.0};
    }
  return b;
}

}  // namespace turtlegas::world
