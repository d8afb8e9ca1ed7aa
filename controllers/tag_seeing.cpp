// SPDX-License-Identifier: MIT
// tag_seeing: tag with eyes. When "it", look with the line camera (Turtle::camera) and steer
// towards the nearest turtle in view (of the colour `prey`, when given), driving at most `step`
// before looking again; with nobody in view, turn on the spot by `search` degrees, and after a
// whole turn with nobody seen sweep a blind leg as tag_chaser does. The turtle it was just tagged
// by is known by its id and skipped until the no-tag-back time has passed. When not "it", keep
// still and flee a touch, as tag_chaser does. Deterministic: the only draws are tag_chaser's
// (Turtle::uniform) for the blind legs.
//   params: declared in tag_seeing_info() below (`turtlegas controllers` lists them)
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "tag_common.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::controllers {

void tag_seeing(turtle::Turtle& t, const turtle::Params& p) {
  const std::string camera = p.get<std::string>("camera");
  std::string prey = p.get<std::string>("prey");
  // Cameras read "#rrggbb" in lower case (a controller sees the controller API only, not the
  // loader's colour names).
  for (char& c : prey) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (!prey.empty() && (prey.size() != 7 || prey[0] != '#' ||
                        !std::all_of(prey.begin() + 1, prey.end(), [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; })))
    throw std::invalid_argument("tag_seeing: prey must be a colour \"#rrggbb\", e.g. \"#e15759\" (got \"" + prey + "\")");
  const double step = p.get<double>("step");
  const double search = p.get<double>("search");
  const double leg = p.get<double>("leg");
  const double no_tag_back = p.get<double>("no_tag_back");
  const double back_off = p.get<double>("back_off");
  const double flee = p.get<double>("flee");

  // Who tagged us, and until when they cannot be tagged back: chasing them is time lost.
  std::string tagger;
  double tagger_until = -std::numeric_limits<double>::infinity();
  t.on_message([&](const turtle::Message& m) {
    if (m.kind() != "tag" || !m.data.value("it", false)) return;
    tagger = m.data.value("by", std::string());
    tagger_until = m.t + no_tag_back;
  });

  std::vector<turtle::Reading> pixels;
  double turned = 0.0;  // degrees turned on the spot since a turtle was last in view
  for (;;) {
    if (!t.it()) {
      turned = 0.0;
      detail::flee_touch(t, t.wait(1.0), flee);
      continue;
    }
    t.camera(camera, pixels);
    const turtle::Reading* target = nullptr;
    for (const turtle::Reading& px : pixels) {
      if (px.kind != "turtle" || (!prey.empty() && px.colour != prey)) continue;
      if (px.what == tagger && t.time() < tagger_until) continue;
      if (!target || px.distance < target->distance) target = &px;
    }
    if (target) {
      turned = 0.0;
      t.right(detail::shortest_turn(target->bearing));
      const turtle::Result moved = t.forward(std::min(step, target->distance));
      if (moved.touched() && moved.touch().kind != "turtle") {
        t.back(back_off);
        detail::turn_away(t, moved.touch().bearing, 70.0);
      }
    } else if (turned < 360.0) {
      t.right(search);
      turned += search;
    } else {
      turned = 0.0;
      detail::after_sweep(t, t.forward(leg * (0.5 + t.uniform())), back_off);
    }
  }
}

turtle::ControllerInfo tag_seeing_info() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  turtle::ControllerInfo info;
  info.summary = "tag: when it, steer at the nearest turtle its camera sees; else keep still";
  info.params = {turtle::string_param("camera", "eye", {}, "the turtle's line camera (a \"camera\" under its \"senses\")"),
                 turtle::string_param("prey", "", {}, "chase only turtles of this colour, \"#rrggbb\"; \"\": any"),
                 turtle::number_param("step", 60.0, 1e-9, inf, "the longest drive towards a turtle in view before looking again, units"),
                 turtle::number_param("search", 45.0, 1e-9, 360.0, "the turn on the spot when nobody is in view, degrees"),
                 turtle::number_param("leg", 300.0, 0, inf, "the blind sweeping leg after a whole turn with nobody seen, units"),
                 turtle::number_param("no_tag_back", 2.0, 0, inf, "how long the last tagger is skipped, seconds (the world's rule)"),
                 turtle::number_param("back_off", 5.0, 0, inf, "how far to back off after running into a wall or ball, units"),
                 turtle::number_param("flee", 60.0, 0, inf, "how far to flee a touch when not it, units")};
  info.restartable = true;  // it reads its Turtle and Params only
  return info;
}

}  // namespace turtlegas::controllers
