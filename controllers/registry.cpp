// SPDX-License-Identifier: MIT
#include "turtlegas/controllers/registry.hpp"

namespace turtlegas::controllers {

void wander(turtle::Turtle&, const turtle::Params&);
void wall_follower(turtle::Turtle&, const turtle::Params&);
void spiral(turtle::Turtle&, const turtle::Params&);
void square(turtle::Turtle&, const turtle::Params&);
void tag_chaser(turtle::Turtle&, const turtle::Params&);
void tag_evader(turtle::Turtle&, const turtle::Params&);
void tag_random(turtle::Turtle&, const turtle::Params&);

turtle::Registry builtin_registry() {
  turtle::Registry r = turtle::base_registry();
  r.add("wander", wander, "go until touched, back off, turn a random angle (step, back_off, max_turn)");
  r.add("wall_follower", wall_follower, "keep a wall on one side (hand: right|left, hop, probe, back_off)");
  r.add("spiral", spiral, "square spiral, sides growing until a touch (start, grow, angle, sides)");
  r.add("square", square, "drive a square (side, laps, left)");
  r.add("tag_chaser", tag_chaser,
        "tag: when it, sweep and lunge at the last tagger; else keep still (leg, lunge, no_tag_back, back_off, flee)");
  r.add("tag_evader", tag_evader, "tag: when not it, follow walls and flee touches (reach, curve, back_off, flee, leg)");
  r.add("tag_random", tag_random, "tag: random legs whatever the role, a baseline (leg, back_off)");
  return r;
}

}  // namespace turtlegas::controllers
