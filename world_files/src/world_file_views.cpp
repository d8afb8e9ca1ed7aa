// SPDX-License-Identifier: MIT
// The world file's `views` key (docs/worlds.md): display windows, read through the one view
// parser (turtle/view.hpp) so that a world file, a program and a protocol message say the same.
#include <string>
#include <vector>

#include "reader.hpp"
#include "turtlegas/sim/suggest.hpp"
#include "turtlegas/turtle/view.hpp"

namespace turtlegas::world::detail {

std::vector<turtle::View> Reader::read_views(const json& v, const sim::WorldDef& def) {
  const std::string path = "/views";
  expect_array(v, path, "views");
  std::vector<turtle::View> views;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string p = at(path, i);
    turtle::View view;
    try {
      view = turtle::parse_view(v[i]);
    } catch (const turtle::ViewError& e) {
      fail(p + e.path, e.what());
    }
    for (std::size_t k = 0; k < views.size(); ++k)
      if (views[k].id == view.id)
        fail(at(p, "id"), "duplicate view id \"" + view.id + "\" (already used at " + at(at(path, k), "id") +
                              "); every view needs its own id");
    if (view.follow) {
      bool found = false;
      std::vector<std::string> ids;
      for (const sim::TurtleDef& t : def.turtles) {
        found = found || t.id == *view.follow;
        if (ids.size() < 20) ids.push_back(t.id);
      }
      if (!found)
        fail(at(p, "follow"), "follow names no turtle: \"" + *view.follow + "\" (the world's turtles: " +
                                  (ids.empty() ? std::string("none") : sim::join_names(ids)) + ")");
    }
    views.push_back(std::move(view));
  }
  return views;
}

}  // namespace turtlegas::world::detail
