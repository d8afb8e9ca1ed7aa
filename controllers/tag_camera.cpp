// SPDX-License-Identifier: MIT
// tag_camera: plays tag as tag_chaser's simpler cousin (when "it", sweep the arena in long legs and
// turn away from what it touches; when not, keep still and flee from a turtle that touches it),
// and keeps a display window on itself while it is "it": it opens a view following itself when it
// becomes "it" and closes it when it tags someone else (Turtle::display(), turtle/view.hpp). The
// view is display data only: the run's physics are those of the same program without it.
//   params: declared in tag_camera_info() below (`turtlegas controllers` lists them)
#include <limits>
#include <optional>
#include <string>

#include "tag_common.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

namespace {

/// Keeps the view on t while it is "it" and closes it otherwise; at most one change per call.
/// Turtles given one shared view id hand it over: the new "it" turns the view onto itself (it may
/// run before the old "it" has closed it), and a turtle closes only a view that follows itself.
void sync_view(turtle::Turtle& t, const turtle::View& view, bool camera) {
  if (!camera) return;
  turtle::Display d = t.display();
  const std::optional<turtle::View> now = d.find(view.id);
  const bool mine = now && now->follow == view.follow;
  if (t.it() && !now) d.open(view);
  else if (t.it() && !mine) d.change(view);
  else if (!t.it() && mine) d.close(view.id);
}

}  // namespace

void tag_camera(turtle::Turtle& t, const turtle::Params& p) {
  const double leg = p.get<double>("leg");
  const double back_off = p.get<double>("back_off");
  const double flee = p.get<double>("flee");
  const bool camera = p.get<bool>("camera");
  turtle::View view;
  view.id = p.get<std::string>("view");
  if (view.id.empty()) view.id = t.id() + "-it";
  view.follow = t.id();
  view.size = {p.get<double>("view_size"), p.get<double>("view_size")};
  view.rotate = p.get<bool>("rotate");
  view.title = t.id() + " is it";

  for (;;) {
    sync_view(t, view, camera);
    if (t.it()) {
      const auto moved = t.forward(leg * (0.5 + t.uniform()));
      sync_view(t, view, camera);
      detail::after_sweep(t, moved, back_off);
    } else {
      const auto still = t.wait(1.0);
      sync_view(t, view, camera);
      detail::flee_touch(t, still, flee);
    }
  }
}

turtle::ControllerInfo tag_camera_info() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  turtle::ControllerInfo info;
  info.summary = "tag: when it, sweep the arena with a view following itself; else keep still and flee";
  info.params = {turtle::number_param("leg", 400.0, 0, inf, "the longest sweeping leg, units"),
                 turtle::number_param("back_off", 5.0, 0, inf, "how far to back off after a touch, units"),
                 turtle::number_param("flee", 60.0, 0, inf, "how far to flee a touch when not it, units"),
                 turtle::number_param("view_size", 200.0, 1e-3, inf, "the width and height of its view, units"),
                 turtle::string_param("view", "", {}, "the view's id; empty: <turtle id>-it"),
                 turtle::boolean_param("camera", true, "whether it opens its view at all (false: plain tag)"),
                 turtle::boolean_param("rotate", false, "whether its view turns with it (heading up)")};
  info.restartable = true;  // it reads its Turtle and Params only (its view is display data)
  return info;
}

}  // namespace turtlegas::controllers
