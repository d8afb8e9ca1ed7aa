// SPDX-License-Identifier: MIT
#include "turtlegas/controllers/registry.hpp"

namespace turtlegas::controllers {

// Each controller's file defines it and its declaration (parameters, restartable).
void wander(turtle::Turtle&, const turtle::Params&);
turtle::ControllerInfo wander_info();
void wall_follower(turtle::Turtle&, const turtle::Params&);
turtle::ControllerInfo wall_follower_info();
void spiral(turtle::Turtle&, const turtle::Params&);
turtle::ControllerInfo spiral_info();
void square(turtle::Turtle&, const turtle::Params&);
turtle::ControllerInfo square_info();
void tag_chaser(turtle::Turtle&, const turtle::Params&);
turtle::ControllerInfo tag_chaser_info();
void tag_evader(turtle::Turtle&, const turtle::Params&);
turtle::ControllerInfo tag_evader_info();
void tag_random(turtle::Turtle&, const turtle::Params&);
turtle::ControllerInfo tag_random_info();
void tag_camera(turtle::Turtle&, const turtle::Params&);
turtle::ControllerInfo tag_camera_info();
void tag_seeing(turtle::Turtle&, const turtle::Params&);
turtle::ControllerInfo tag_seeing_info();
void braitenberg(turtle::Turtle&, const turtle::Params&);
turtle::ControllerInfo braitenberg_info();
void epuck_swarm(turtle::Turtle&, const turtle::Params&);
turtle::ControllerInfo epuck_swarm_info();

turtle::Registry builtin_registry() {
  turtle::Registry r = turtle::base_registry();
  r.add("wander", wander, wander_info());
  r.add("wall_follower", wall_follower, wall_follower_info());
  r.add("spiral", spiral, spiral_info());
  r.add("square", square, square_info());
  r.add("tag_chaser", tag_chaser, tag_chaser_info());
  r.add("tag_evader", tag_evader, tag_evader_info());
  r.add("tag_random", tag_random, tag_random_info());
  r.add("tag_camera", tag_camera, tag_camera_info());
  r.add("tag_seeing", tag_seeing, tag_seeing_info());
  r.add("braitenberg", braitenberg, braitenberg_info());
  r.add("epuck_swarm", epuck_swarm, epuck_swarm_info());
  return r;
}

}  // namespace turtlegas::controllers
