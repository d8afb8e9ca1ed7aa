// SPDX-License-Identifier: MIT
// Views: display windows onto a world (AI Memo 272's "a fixed window or a window moving with a
// given turtle, or many of these simultaneously ... under (real-time) program control").
//
// A view is data, the same everywhere: the world file's `"views"` list, the Display handle of a
// controller (Turtle::display()), the protocol's view_open/view_change/view_close, the viewer and
// the renderer all read and write this struct, through one JSON form (view_to_json, parse_view):
//
//   {"id": "chase", "follow": "t1", "offset": [0, 40], "size": [200, 150], "rotate": true,
//    "layers": ["walls", "turtles", "trails"], "title": "t1's view"}
//
// A view is display data, never physics: opening, changing or closing one is logged as a `view`
// event (docs/viewer.md) and changes nothing else in a run.
//
// Geometry (view_transform): view coordinates have their origin at the view's centre, x to the
// right and y up, in world units; the view shows [-w/2, w/2] x [-h/2, h/2] of them. A fixed view's
// centre is `center`, its axes the world's. A follow view's centre is the followed turtle's
// position plus `offset`; with `rotate` the offset is in the turtle's frame ([dx, dy] = dx to its
// right, dy ahead of it) and the view turns with the turtle so that its heading points up.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/vec2.hpp"

namespace turtlegas::turtle {

/// What a view draws, one bit each (View::layers).
enum ViewLayer : std::uint32_t {
  kLayerWalls = 1u << 0,
  kLayerBalls = 1u << 1,
  kLayerTurtles = 1u << 2,
  kLayerTrails = 1u << 3,
  kLayerSensors = 1u << 4,  ///< the flash on a sensor arc that fired
  kLayerRoles = 1u << 5,    ///< tag roles ("it" marked)
  kLayersAll = (1u << 6) - 1,
};
/// The layers' names, bit k's name at index k: walls, balls, turtles, trails, sensors, roles.
const std::vector<std::string_view>& view_layer_names();

struct View {
  std::string id;
  std::optional<std::string> follow;  ///< the followed turtle's id; nullopt: a fixed view
  sim::Vec2 center;                   ///< fixed views: the world point at the view's centre
  sim::Vec2 offset;                   ///< follow views: the centre's offset from the turtle
  sim::Vec2 size{200.0, 200.0};       ///< width and height, world units, > 0
  bool rotate = false;                ///< follow views: turn with the turtle (heading up)
  std::uint32_t layers = kLayersAll;  ///< ViewLayer bits
  std::string title;                  ///< shown above the view; empty: the id
  bool operator==(const View&) const = default;
};

/// A view's JSON form (the header comment's), with every key: {"id", "follow" (a string or null),
/// "center" or "offset" (the one that applies), "size", "rotate", "layers" (names), "title"}.
nlohmann::json view_to_json(const View& v);
/// The same as JSON text in the event log's style: keys in the order above, `", "` and `": "`
/// between them, numbers as the shortest decimal that reads back the same.
std::string view_json_text(const View& v);

/// A view that is not valid, with the JSON pointer of the culprit relative to the view object
/// ("" for the object itself, "/size/0", ...); what() says what is wrong and how to fix it.
struct ViewError : std::invalid_argument {
  ViewError(std::string path, const std::string& message) : std::invalid_argument(message), path(std::move(path)) {}
  std::string path;
};

/// Reads a view from its JSON form. With `base`, `j` is a change to *base: the keys it has replace
/// base's ("follow": null makes the view fixed, at the centre it showed last is the caller's
/// business), and "id" may be left out; without `base` "id" is required and the rest defaults as
/// View does. Unknown keys, "center" on a follow view, "offset" on a fixed one, a size that is not
/// two numbers > 0, a layer name that is not known: ViewError. Turtle ids are not checked here
/// (the world file's loader and the world server do that).
View parse_view(const nlohmann::json& j, const View* base = nullptr);

/// Where a followed turtle is: its position and heading (radians, Logo convention: 0 is +y,
/// clockwise positive).
struct FollowPose {
  sim::Vec2 pos;
  double heading = 0.0;
};

/// World to view coordinates and back, for one view at one instant (view_transform).
struct ViewTransform {
  sim::Vec2 center;     ///< the world point at the view's centre
  sim::Vec2 right{1.0, 0.0};  ///< the world direction of the view's +x (unit)
  sim::Vec2 up{0.0, 1.0};     ///< the world direction of the view's +y (unit)
  sim::Vec2 size;       ///< the view's width and height, world units

  /// A world point in view coordinates (origin at the centre, x right, y up).
  sim::Vec2 to_view(sim::Vec2 world) const {
    const sim::Vec2 d{world.x - center.x, world.y - center.y};
    return {d.x * right.x + d.y * right.y, d.x * up.x + d.y * up.y};
  }
  /// A view point back in world coordinates.
  sim::Vec2 to_world(sim::Vec2 view) const {
    return {center.x + view.x * right.x + view.y * up.x, center.y + view.x * right.y + view.y * up.y};
  }
  /// A world point on a picture of width x height pixels showing the view (pixel (0, 0) at the
  /// top left, y down; the view's size is stretched to the picture's).
  sim::Vec2 to_pixels(sim::Vec2 world, double width, double height) const {
    const sim::Vec2 v = to_view(world);
    return {(v.x / size.x + 0.5) * width, (0.5 - v.y / size.y) * height};
  }
  /// A world direction's angle on the picture: how far a heading (radians, Logo) is turned
  /// clockwise from the picture's up.
  double heading_on_view(double heading) const { return heading - std::atan2(up.x, up.y); }
  /// Whether a disc of radius r at world point p shows (at least in part) in the view.
  bool shows(sim::Vec2 p, double r) const {
    const sim::Vec2 v = to_view(p);
    return std::abs(v.x) <= size.x / 2 + r && std::abs(v.y) <= size.y / 2 + r;
  }
};

/// The view's transform now. `followed`: the followed turtle's pose (ignored by a fixed view); a
/// follow view without one (its turtle is not in the world) shows its `center`, unturned.
ViewTransform view_transform(const View& v, std::optional<FollowPose> followed);

/// One change to a world's views, as the event log has it (the `view` event's "op").
enum class ViewOp { open, change, close };
std::string_view to_string(ViewOp op);

class Agent;  // the runtime's side of a turtle

/// A controller program's handle on the world's views (Turtle::display()). Changes apply at once,
/// at the control boundary at which the program runs, are logged as `view` events (by the
/// turtle's id) and show in the next frame; they never change the physics.
class Display {
 public:
  explicit Display(Agent& agent) : agent_(&agent) {}
  /// Opens view v. Throws std::invalid_argument when its id is taken, its follow names no turtle,
  /// or it is not valid (ViewError).
  void open(const View& v);
  /// Replaces the view with v's id by v. Throws std::invalid_argument as open() does, and when no
  /// view has that id.
  void change(const View& v);
  /// Closes the view; false when no view has that id.
  bool close(const std::string& id);
  /// The view with that id, if one is open.
  std::optional<View> find(const std::string& id) const;
  /// Every open view, in the order they were opened.
  std::vector<View> views() const;

 private:
  Agent* agent_;
};

}  // namespace turtlegas::turtle
