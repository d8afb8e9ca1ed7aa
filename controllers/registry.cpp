// SPDX-License-Identifier: MIT
#include "turtlegas/controllers/registry.hpp"

namespace turtlegas::controllers {

void wander(turtle::Turtle&, const turtle::Params&);
void wall_follower(turtle::Turtle&, const turtle::Params&);
void spiral(turtle::Turtle&, const turtle::Params&);
void square(turtle::Turtle&, const turtle::Params&);

turtle::Registry builtin_registry() {
  turtle::Registry r = turtle::base_registry();
  r.add("wander", wander, "go until touched, back off, turn a random angle (step, back_off, max_turn)");
  r.add("wall_follower", wall_follower, "keep a wall on one side (hand: right|left, hop, probe, back_off)");
  r.add("spiral", spiral, "square spiral, sides growing until a touch (start, grow, angle, sides)");
  r.add("square", square, "drive a square (side, laps, left)");
  return r;
}

}  // namespace turtlegas::controllers
