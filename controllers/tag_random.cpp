// SPDX-License-Identifier: MIT
// tag_random: the baseline. Ignores its role: legs of random length in random directions,
// backing off from whatever it touches.
//   params: declared in tag_random_info() below (`turtlegas controllers` lists them)
#include <limits>

#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void tag_random(turtle::Turtle& t, const turtle::Params& p) {
  const double leg = p.get<double>("leg");
  const double back_off = p.get<double>("back_off");
  for (;;) {
    if (t.forward(leg * t.uniform()).touched()) t.back(back_off);
    t.right((2.0 * t.uniform() - 1.0) * 180.0);
  }
}

turtle::ControllerInfo tag_random_info() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  turtle::ControllerInfo info;
  info.summary = "tag: random legs whatever the role, a baseline";
  info.params = {turtle::number_param("leg", 300.0, 0, inf, "the longest leg, units"),
                 turtle::number_param("back_off", 5.0, 0, inf, "how far to back off after a touch, units")};
  info.restartable = true;  // it reads its Turtle and Params only
  return info;
}

}  // namespace turtlegas::controllers
