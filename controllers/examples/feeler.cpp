// SPDX-License-Identifier: MIT
// feeler: the wall follower sketched in the design, made real, as a plugin that `turtlegas run
// --plugin` loads without rebuilding turtlegas (docs/controllers.md walks through it).
//
// Follow a wall on the right: go until something is touched, back off, turn left (a right angle if
// the touch was in front, a little otherwise), then curve back towards the wall. Without the curve
// back it would just bounce round the room; with it, it hugs the wall.
//   params: declared in turtlegas_register below (back_off, curve, reach)
#include <limits>
#include <string>
#include <utility>

#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/registry.hpp"  // for turtle::Registry, in turtlegas_register only

namespace {

void feeler(turtlegas::turtle::Turtle& t, const turtlegas::turtle::Params& p) {
  // Their defaults come from the declaration below.
  const double back_off = p.get<double>("back_off");
  const double curve = p.get<double>("curve");
  const double reach = p.get<double>("reach");
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
/// against, before it loads the world. The declaration gives the parameters (checked when a world
/// is loaded, listed by `turtlegas controllers`) and says that the program is restartable: it
/// reads its Turtle and Params only, so a checkpointed run can be resumed by replaying it.
extern "C" void turtlegas_register(turtlegas::turtle::Registry& registry) {
  namespace tt = turtlegas::turtle;
  constexpr double inf = std::numeric_limits<double>::infinity();
  tt::ControllerInfo info;
  info.summary = "wall on the right by feel: forward until touched, back off, turn left";
  info.params = {tt::number_param("back_off", 5.0, 0, inf, "how far to back off after a touch, units"),
                 tt::number_param("curve", 20.0, -360, 360, "the turn back towards the wall, degrees"),
                 tt::number_param("reach", 40.0, 0, inf, "how far to feel ahead, units")};
  info.restartable = true;
  registry.add("feeler", feeler, std::move(info));
}
