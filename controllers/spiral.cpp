// SPDX-License-Identifier: MIT
// spiral: the Logo square spiral. Each side is `grow` longer than the last; a touch ends it.
//   params: declared in spiral_info() below (`turtlegas controllers` lists them)
#include <limits>

#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void spiral(turtle::Turtle& t, const turtle::Params& p) {
  double side = p.get<double>("start");
  const double grow = p.get<double>("grow");
  const double angle = p.get<double>("angle");
  const int sides = p.get<int>("sides");
  for (int k = 0; k < sides; ++k) {
    if (t.forward(side).touched()) return;  // ran into something: done
    t.right(angle);
    side += grow;
  }
}

turtle::ControllerInfo spiral_info() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  turtle::ControllerInfo info;
  info.summary = "square spiral, sides growing until a touch";
  info.params = {turtle::number_param("start", 5.0, 0, inf, "the first side, units"),
                 turtle::number_param("grow", 5.0, -inf, inf, "added to each side, units"),
                 turtle::number_param("angle", 90.0, -360, 360, "the turn after each side, degrees"),
                 turtle::integer_param("sides", 200, 0, 1000000000, "how many sides at most")};
  info.restartable = true;  // it reads its Turtle and Params only
  return info;
}

}  // namespace turtlegas::controllers
