// SPDX-License-Identifier: MIT
// square: drive a square, `laps` times (0: forever). A touch makes it turn the corner early.
//   params: declared in square_info() below (`turtlegas controllers` lists them)
#include <limits>

#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void square(turtle::Turtle& t, const turtle::Params& p) {
  const double side = p.get<double>("side");
  const int laps = p.get<int>("laps");
  const bool left = p.get<bool>("left");
  for (int lap = 0; laps == 0 || lap < laps; ++lap)
    for (int k = 0; k < 4; ++k) {
      t.forward(side);
      if (left) t.left(90);
      else t.right(90);
    }
}

turtle::ControllerInfo square_info() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  turtle::ControllerInfo info;
  info.summary = "drive a square";
  info.params = {turtle::number_param("side", 100.0, 0, inf, "the side, units"),
                 turtle::integer_param("laps", 0, 0, 1000000000, "how many laps (0: for ever)"),
                 turtle::boolean_param("left", false, "counter-clockwise (left turns)")};
  info.restartable = true;  // it reads its Turtle and Params only
  return info;
}

}  // namespace turtlegas::controllers
