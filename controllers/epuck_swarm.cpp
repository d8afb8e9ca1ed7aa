// SPDX-License-Identifier: MIT
// epuck_swarm: the obstacle avoider of an e-puck swarm, on an infrared ring and two wheels (the
// loop Enki's e-puck examples run). Each control step it reads its ring and sets its wheels for one
// step: full speed ahead, the wheel on the side of a near obstacle slowed (a nearer obstacle,
// more), and away on the spot when something is close ahead. Proximity is 1 at the turtle's rim
// and 0 at the ring's range. A touch ends the step's arc early; the next step steers again.
//   params: declared in epuck_swarm_info() below (`turtlegas controllers` lists them)
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void epuck_swarm(turtle::Turtle& t, const turtle::Params& p) {
  const auto sensor = p.get<std::string>("sensor");
  const double gain = p.get<double>("gain");
  // "sense": 0 drives blind (the same loop with every ray reading nothing); 2 reads the ring and
  // drives blind all the same: the motion of 0 and the reading of 1, so 2 - 0 is what sensing costs.
  const double mode = p.get<double>("sense");
  const bool sense = mode == 1.0, read = mode != 0.0;
  const double v = t.speed();
  const double reach = p.get<double>("reach");
  std::vector<turtle::Reading> ring;
  for (;;) {
    double left = 0.0, right = 0.0, front = 0.0;
    if (read) t.scan(sensor, ring);
    if (sense) {
      for (const turtle::Reading& r : ring) {
        const double b = std::remainder(r.bearing, 360.0);  // (-180, 180]: negative on the left
        const double near = std::clamp(1.0 - (r.distance - t.radius()) / reach, 0.0, 1.0);
        if (b > 0.0 && b < 150.0) right = std::max(right, near);
        if (b < 0.0 && b > -150.0) left = std::max(left, near);
        if (std::fabs(b) < 30.0) front = std::max(front, near);
      }
    }
    // An obstacle on the right slows the left wheel, so the turtle turns left, away from it;
    // one ahead turns it on the spot, towards the roomier side.
    double l = v * (1.0 - gain * right + gain * left), r = v * (1.0 - gain * left + gain * right);
    if (front > 0.5) {
      l = right > left ? -v : v;
      r = -l;
    }
    t.wheels(std::clamp(l, -v, v), std::clamp(r, -v, v), t.dt());
  }
}

turtle::ControllerInfo epuck_swarm_info() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  turtle::ControllerInfo info;
  info.summary = "an e-puck swarm's obstacle avoider: an infrared ring steering two wheels";
  info.params = {
      turtle::string_param("sensor", "ir", {}, "the range sensor to steer by: a ring (the turtle's \"senses\")"),
      turtle::number_param("gain", 1.0, 0, inf, "how much a side's proximity (0 at the range, 1 at the rim) slows the wheel on that side"),
      turtle::number_param("reach", 12.0, 1e-9, inf, "units beyond the rim where proximity falls to 0 (the ring's range less the radius)"),
      turtle::number_param("sense", 1.0, 0, 2, "1 reads the ring each step; 0 drives blind; 2 reads it and drives blind (2 - 0: what sensing costs)")};
  info.restartable = true;  // it reads its Turtle and Params only
  return info;
}

}  // namespace turtlegas::controllers
