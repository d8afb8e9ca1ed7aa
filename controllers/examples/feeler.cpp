// SPDX-License-Identifier: MIT
// feeler: the wall follower sketched in the design, made real, as a plugin that `turtlegas run
// --plugin` loads without rebuilding turtlegas (docs/controllers.md walks through it).
//
// Follow a wall on the right: go until something is touched, back off, turn left (a right angle if
// the touch was in front, a little otherwise), then curve back towards the wall. Without the curve
// back it would just bounce round the room; with it, it hugs the wall.
//   params: back_off (units, default 5), curve (degrees, default 20), reach (units, default 40)
#include <string>

#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/registry.hpp"  // for turtle::Registry, in turtlegas_register only

namespace {

void feeler(turtlegas::turtle::Turtle& t, const turtlegas::turtle::Params& p) {
  const double back_off = p.get("back_off", 5.0);
  const double curve = p.get("curve", 20.0);
  const double reach = p.get("reach", 40.0);
  // An interrupt handler: runs in this program, for each touch, before the command it cut short
  // returns.
  int touches = 0;
  t.on_touch([&](const turtlegas::turtle::Touch& touch) {
    if (++touches % 25 == 0) t.log(std::to_string(touches) + " touches; the last on " + touch.what);
  });
  for (;;) {
    auto moved = t.forward(reach);  // suspends until done or touched
    if (moved.touched()) {
      t.back(back_off);
      t.left(moved.touch().front() ? 90 : 30);
    } else {
      t.right(curve);  // nothing within reach: lean back towards where the wall was
    }
  }
}

}  // namespace

/// The plugin's entry point: turtlegas calls it once, with the registry world files are checked
/// against, before it loads the world.
extern "C" void turtlegas_register(turtlegas::turtle::Registry& registry) {
  registry.add("feeler", feeler, "wall on the right by feel: forward until touched, back off, turn left (back_off, curve, reach)");
}
