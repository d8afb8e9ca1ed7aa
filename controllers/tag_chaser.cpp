// SPDX-License-Identifier: MIT
// tag_chaser: when "it", sweep the arena in long legs and, after being tagged, wait out the
// no-tag-back interval facing the tagger and lunge at it; when not "it", keep still (a still
// turtle is the hardest to run into) and flee from any turtle that touches it.
//   params: leg (units, default 400), lunge (units, 80), no_tag_back (s, the world's rule, 2),
//           back_off (units, 5), flee (units, 60)
#include <algorithm>
#include <optional>
#include <string>

#include "tag_common.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void tag_chaser(turtle::Turtle& t, const turtle::Params& p) {
  const double leg = p.get("leg", 400.0);
  const double lunge = p.get("lunge", 80.0);
  const double no_tag_back = p.get("no_tag_back", 2.0);
  const double back_off = p.get("back_off", 5.0);
  const double flee = p.get("flee", 60.0);

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
      const auto moved = t.forward(leg * (0.5 + t.uniform()));
      if (moved.touched()) {
        if (moved.touch().kind != "turtle") t.back(back_off);
        detail::turn_away(t, moved.touch().bearing, 70.0);
      } else {
        t.right((2.0 * t.uniform() - 1.0) * 90.0);
      }
    } else {
      pending.reset();
      const auto still = t.wait(1.0);
      if (still.touched() && still.touch().kind == "turtle" && !t.it()) {
        detail::turn_away(t, still.touch().bearing, 30.0);
        t.forward(flee);
      }
    }
  }
}

}  // namespace turtlegas::controllers
