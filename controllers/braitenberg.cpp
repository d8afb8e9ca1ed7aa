// SPDX-License-Identifier: MIT
// braitenberg: a vehicle that wanders on its infrared ring and never touches a wall. Each control
// step it reads its ring; when the front half is clear it steers away from the nearer side (more
// the nearer it is: Braitenberg's vehicle 3b, the explorer) and drives one short stroke, else it
// turns on the spot towards the roomier side. A turn never collides, so only a stroke can touch.
//   params: declared in braitenberg_info() below (`turtlegas controllers` lists them)
//
// Why it never touches a wall of a convex room (docs/controllers.md, "braitenberg"): for each wall
// whose normal (from the turtle towards the wall) is within 90 degrees of the heading, some ray of
// an n-ray ring is within 180/n degrees of that normal, and in a convex room a ray reads at most
// the wall line's distance p over the cosine of its angle to the normal. So with every ray of the
// front half (bearings within 90 + 180/n of the heading) reading at least T, p >= T cos(180/n);
// a stroke of s brings the turtle at most s nearer, and T > (r + s) / cos(180/n) keeps it clear.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void braitenberg(turtle::Turtle& t, const turtle::Params& p) {
  const auto sensor = p.get<std::string>("sensor");
  const double clearance = p.get<double>("clearance");
  const double gain = p.get<double>("gain");
  const double max_turn = p.get<double>("turn");
  // One stroke a control step at most: the ring is read again before the next.
  const double stroke = std::min(p.get<double>("step"), t.speed() * t.dt());
  std::vector<turtle::Reading> ring;
  t.scan(sensor, ring);
  const double half_gap = 180.0 / static_cast<double>(ring.size());
  const double needed = (t.radius() + stroke) / std::cos(half_gap * std::numbers::pi / 180.0);
  const double threshold = std::max(clearance, needed * (1.0 + 1e-9));
  for (;;) {
    double front = std::numeric_limits<double>::infinity();
    double left = front, right = front;
    for (const turtle::Reading& r : ring) {
      const double b = std::remainder(r.bearing, 360.0);  // (-180, 180]: negative on the left
      if (std::fabs(b) <= 90.0 + half_gap) front = std::min(front, r.distance);
      if (b > 0.0 && b < 180.0) right = std::min(right, r.distance);
      if (b < 0.0 && b > -180.0) left = std::min(left, r.distance);
    }
    if (front >= threshold) {
      // Steer away from the nearer side, by how much nearer it is (in proximity, 1/distance).
      const double pull = gain * t.radius() * (1.0 / left - 1.0 / right);
      const double turn = std::clamp(pull, -max_turn, max_turn) + (2.0 * t.uniform() - 1.0) * 0.1 * max_turn;
      if (std::fabs(turn) > 1e-9) t.right(turn);
      t.scan(sensor, ring);  // the turn changed what lies ahead
      bool clear = true;
      for (const turtle::Reading& r : ring)
        if (std::fabs(std::remainder(r.bearing, 360.0)) <= 90.0 + half_gap && r.distance < threshold) clear = false;
      if (clear) t.forward(stroke);
    } else if (right > left) {
      t.right(max_turn);
    } else {
      t.left(max_turn);
    }
    t.scan(sensor, ring);
  }
}

turtle::ControllerInfo braitenberg_info() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  turtle::ControllerInfo info;
  info.summary = "wander on an infrared ring without touching (Braitenberg's explorer)";
  info.params = {
      turtle::string_param("sensor", "ir", {}, "the range sensor to steer by: a ring (the turtle's \"senses\")"),
      turtle::number_param("clearance", 0.0, 0, inf,
                           "drive only while the front half reads at least this far, units (never less than the "
                           "no-touch bound (radius + step) / cos(180/n))"),
      turtle::number_param("gain", 60.0, 0, inf, "degrees of steering per unit of proximity difference (radius / distance)"),
      turtle::number_param("turn", 30.0, 0, 180, "the largest turn at once, degrees"),
      turtle::number_param("step", 1e9, 0, inf, "the longest stroke, units (never more than speed x dt)")};
  info.restartable = true;  // it reads its Turtle and Params only
  return info;
}

}  // namespace turtlegas::controllers
