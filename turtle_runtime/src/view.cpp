// SPDX-License-Identifier: MIT
// Views (view.hpp): their one JSON form, their geometry, and the Display handle's bodies.
#include "turtlegas/turtle/view.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "turtlegas/sim/format.hpp"
#include "turtlegas/turtle/json_kind.hpp"


namespace turtlegas::turtle {

using json = nlohmann::json;

const std::vector<std::string_view>& view_layer_names() {
  static const std::vector<std::string_view> names = {"walls", "balls", "turtles", "trails", "sensors", "roles"};
  return names;
}

std::string_view to_string(ViewOp op) {
  switch (op) {
    case ViewOp::open: return "open";
    case ViewOp::change: return "change";
    case ViewOp::close: return "close";
  }
  return "?";
}

json view_to_json(const View& v) {
  json j = json::object();
  j["id"] = v.id;
  j["follow"] = v.follow ? json(*v.follow) : json(nullptr);
  if (v.follow) j["offset"] = {v.offset.x, v.offset.y};
  else j["center"] = {v.center.x, v.center.y};
  j["size"] = {v.size.x, v.size.y};
  j["rotate"] = v.rotate;
  json layers = json::array();
  for (std::size_t k = 0; k < view_layer_names().size(); ++k)
    if ((v.layers >> k) & 1u) layers.push_back(view_layer_names()[k]);
  j["layers"] = layers;
  j["title"] = v.title;
  return j;
}

std::string view_json_text(const View& v) {
  auto str = [](const std::string& s) { return json(s).dump(-1, ' ', false, json::error_handler_t::replace); };
  auto pair = [](sim::Vec2 p) { return "[" + sim::format_number(p.x) + ", " + sim::format_number(p.y) + "]"; };
  std::string out = "{\"id\": " + str(v.id) + ", \"follow\": " + (v.follow ? str(*v.follow) : std::string("null"));
  out += v.follow ? ", \"offset\": " + pair(v.offset) : ", \"center\": " + pair(v.center);
  out += ", \"size\": " + pair(v.size) + (v.rotate ? ", \"rotate\": true" : ", \"rotate\": false") + ", \"layers\": [";
  bool first = true;
  for (std::size_t k = 0; k < view_layer_names().size(); ++k)
    if ((v.layers >> k) & 1u) {
      out += first ? "\"" : ", \"";
      out += view_layer_names()[k];
      out += '"';
      first = false;
    }
  out += "], \"title\": " + str(v.title) + "}";
  return out;
}

namespace {

sim::Vec2 pair(const json& v, const std::string& path, const char* what, bool positive) {
  if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
    throw ViewError(path, path.substr(1) + " must be [" + what + "], two numbers, got " +
                              (v.is_array() ? "an array of " + std::to_string(v.size()) : json_kind(v)));
  const sim::Vec2 p{v[0].get<double>(), v[1].get<double>()};
  for (int k = 0; k < 2; ++k) {
    const double x = k == 0 ? p.x : p.y;
    if (!std::isfinite(x) || (positive && !(x > 0.0)))
      throw ViewError(path + "/" + std::to_string(k),
                      path.substr(1) + " must be [" + what + "], two " + (positive ? "numbers > 0" : "finite numbers") +
                          ", got " + v.dump());
  }
  return p;
}

}  // namespace

View parse_view(const json& j, const View* base) {
  if (!j.is_object())
    throw ViewError("", "a view must be a JSON object such as {\"id\": \"v1\", \"center\": [250, 200], \"size\": [500, 400]}, got " +
                            json_kind(j));
  static constexpr std::string_view keys[] = {"id", "follow", "center", "offset", "size", "rotate", "layers", "title"};
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it.key().starts_with("x-")) continue;
    if (std::find(std::begin(keys), std::end(keys), it.key()) == std::end(keys))
      throw ViewError("/" + it.key(), "unknown key \"" + it.key() +
                                          "\" in a view (known keys: id, follow, center, offset, size, rotate, layers, "
                                          "title; keys starting with x- are ignored)");
  }
  View v = base ? *base : View{};
  if (const auto it = j.find("id"); it != j.end()) {
    if (!it->is_string() || it->get_ref<const std::string&>().empty() || it->get_ref<const std::string&>().size() > 200)
      throw ViewError("/id", "id must be a non-empty string of at most 200 characters, got " + json_kind(*it));
    if (base && it->get_ref<const std::string&>() != base->id)
      throw ViewError("/id", "a change cannot rename view \"" + base->id + "\"; close it and open a new one");
    v.id = it->get<std::string>();
  } else if (!base) {
    throw ViewError("", "a view needs an \"id\", e.g. {\"id\": \"v1\", \"center\": [250, 200], \"size\": [500, 400]}");
  }
  if (const auto it = j.find("follow"); it != j.end()) {
    if (it->is_null()) v.follow.reset();
    else if (it->is_string() && !it->get_ref<const std::string&>().empty()) v.follow = it->get<std::string>();
    else throw ViewError("/follow", "follow must be a turtle's id or null (a fixed view), got " + json_kind(*it));
  }
  if (const auto it = j.find("center"); it != j.end()) {
    if (v.follow)
      throw ViewError("/center", "center is for fixed views; a view that follows a turtle is placed by \"offset\" "
                                 "(from the turtle), or set \"follow\": null");
    v.center = pair(*it, "/center", "x, y", false);
  }
  if (const auto it = j.find("offset"); it != j.end()) {
    if (!v.follow)
      throw ViewError("/offset", "offset is for views that follow a turtle; a fixed view is placed by \"center\", "
                                 "or add \"follow\": \"<turtle id>\"");
    v.offset = pair(*it, "/offset", "dx, dy", false);
  }
  if (const auto it = j.find("size"); it != j.end()) v.size = pair(*it, "/size", "width, height", true);
  if (const auto it = j.find("rotate"); it != j.end()) {
    if (!it->is_boolean()) throw ViewError("/rotate", "rotate must be true or false, got " + json_kind(*it));
    v.rotate = it->get<bool>();
    if (v.rotate && !v.follow)
      throw ViewError("/rotate", "rotate turns a view with the turtle it follows; a fixed view cannot rotate "
                                 "(add \"follow\": \"<turtle id>\" or set rotate to false)");
  }
  if (!v.follow) v.rotate = false;  // a change that made the view fixed
  if (const auto it = j.find("layers"); it != j.end()) {
    const std::string known = "walls, balls, turtles, trails, sensors, roles";
    if (it->is_string() && it->get_ref<const std::string&>() == "all") {
      v.layers = kLayersAll;
    } else if (it->is_array()) {
      v.layers = 0;
      for (std::size_t k = 0; k < it->size(); ++k) {
        const json& n = (*it)[k];
        const std::string p = "/layers/" + std::to_string(k);
        if (!n.is_string()) throw ViewError(p, "a layer is a name (" + known + "), got " + json_kind(n));
        const auto& names = view_layer_names();
        const auto f = std::find(names.begin(), names.end(), n.get_ref<const std::string&>());
        if (f == names.end())
          throw ViewError(p, "unknown layer \"" + n.get<std::string>().substr(0, 64) + "\" (known: " + known + ")");
        v.layers |= 1u << static_cast<unsigned>(f - names.begin());
      }
    } else {
      throw ViewError("/layers", "layers must be \"all\" or a list of names (" + known + "), got " + json_kind(*it));
    }
  }
  if (const auto it = j.find("title"); it != j.end()) {
    if (!it->is_string()) throw ViewError("/title", "title must be a string, got " + json_kind(*it));
    v.title = it->get<std::string>();
  }
  return v;
}

ViewTransform view_transform(const View& v, std::optional<FollowPose> followed) {
  ViewTransform t;
  t.size = v.size;
  if (!v.follow || !followed) {
    t.center = v.center;
    return t;
  }
  if (!v.rotate) {
    t.center = followed->pos + v.offset;
    return t;
  }
  // Logo heading h: ahead is (sin h, cos h), to the right (cos h, -sin h).
  const double s = std::sin(followed->heading), c = std::cos(followed->heading);
  t.up = {s, c};
  t.right = {c, -s};
  t.center = followed->pos + v.offset.x * t.right + v.offset.y * t.up;
  return t;
}

}  // namespace turtlegas::turtle
