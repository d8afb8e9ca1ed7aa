// SPDX-License-Identifier: MIT
// wander: go until something is touched, back off, turn a random angle, repeat.
//   params: declared in wander_info() below (`turtlegas controllers` lists them)
#include <limits>

#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void wander(turtle::Turtle& t, const turtle::Params& p) {
  const double step = p.get<double>("step");
  const double back_off = p.get<double>("back_off");
  const double max_turn = p.get<double>("max_turn");
  for (;;) {
    const auto moved = t.forward(step);
    if (moved.touched()) t.back(back_off);
    // A random turn either way; uniform() is the turtle's own seeded stream, so runs repeat.
    t.right((2.0 * t.uniform() - 1.0) * max_turn);
  }
}

turtle::ControllerInfo wander_info() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  turtle::ControllerInfo info;
  info.summary = "go until touched, back off, turn a random angle";
  info.params = {turtle::number_param("step", 1000.0, 0, inf, "how far to drive before turning, units"),
                 turtle::number_param("back_off", 5.0, 0, inf, "how far to back off after a touch, units"),
                 turtle::number_param("max_turn", 180.0, 0, 360, "the largest turn either way, degrees")};
  info.restartable = true;  // it reads its Turtle and Params only
  return info;
}

}  // namespace turtlegas::controllers
