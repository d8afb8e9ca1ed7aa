// SPDX-License-Identifier: MIT
// tag_chaser: when "it", sweep the arena in long legs and, after being tagged, wait out the
// no-tag-back interval facing the tagger and lunge at it; when not "it", keep still (a still
// turtle is the hardest to run into) and flee from any turtle that touches it.
//   params: declared in tag_chaser_info() below (`turtlegas controllers` lists them)
#include <algorithm>
#include <optional>
#include <string>

#include "tag_common.hpp"
#include <limits>

#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void tag_chaser(turtle::Turtle& t, const turtle::Params& p) {
  const double leg = p.get<double>("leg");
  const double lunge = p.get<double>("lunge");
  const double no_tag_back = p.get<double>("no_tag_back");
  const double back_off = p.get<double>("back_off");
  const double flee = p.get<double>("flee");

  // The last turtle that touched us, and where: a tag's message follows its touch at the same
  // control step, so the tagger's bearing is known when the message says we are "it".
  std::optional<turtle::Touch> last_turtle_touch;
  struct Lunge {
    double bearing;  // degrees, relative to the heading at the time of the tag
    double after;    // seconds: when the tagger can be tagged back
  };
  std::optional<Lunge> pending;
  t.on_touch([&](const turtle::Touch& touch) {
    if (touch.kind == "turtle") last_turtle_touch = touch;
  });
  t.on_message([&](const turtle::Message& m) {
    if (m.kind() != "tag" || !m.data.value("it", false)) return;
    const std::string by = m.data.value("by", std::string());
    if (last_turtle_touch && last_turtle_touch->what == by)
      pending = Lunge{last_turtle_touch->bearing, m.t + no_tag_back};
  });

  for (;;) {
    if (t.it()) {
      if (pending) {
        const Lunge l = *pending;
        pending.reset();
        t.right(detail::shortest_turn(l.bearing));
        if (t.time() < l.after) t.wait(l.after - t.time() + 0.05);
        if (!t.it()) continue;
        t.forward(lunge);
        continue;
      }
      detail::after_sweep(t, t.forward(leg * (0.5 + t.uniform())), back_off);
    } else {
      pending.reset();
      detail::flee_touch(t, t.wait(1.0), flee);
    }
  }
}

turtle::ControllerInfo tag_chaser_info() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  turtle::ControllerInfo info;
  info.summary = "tag: when it, sweep and lunge at the last tagger; else keep still";
  info.params = {turtle::number_param("leg", 400.0, 0, inf, "the longest sweeping leg, units"),
                 turtle::number_param("lunge", 80.0, 0, inf, "the lunge at the tagger, units"),
                 turtle::number_param("no_tag_back", 2.0, 0, inf, "how long to wait before lunging, seconds (the world's rule)"),
                 turtle::number_param("back_off", 5.0, 0, inf, "how far to back off after a touch, units"),
                 turtle::number_param("flee", 60.0, 0, inf, "how far to flee a touch when not it, units")};
  info.restartable = true;  // it reads its Turtle and Params only
  return info;
}

}  // namespace turtlegas::controllers
