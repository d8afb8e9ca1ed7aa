// SPDX-License-Identifier: MIT
// The protocol's view messages (docs/protocol.md, "Views: view_open, view_change, view_close"):
// display windows opened, changed and closed by a client. A view is display data: the change
// applies at once (also while the world is paused) at the current control boundary, is logged as a
// `view` event and shows in every subscriber's next frame; it is not an input of the world (the
// physics never see it), so the input log leaves it out.
#include <string>

#include <nlohmann/json.hpp>

#include "turtlegas/server/protocol.hpp"
#include "turtlegas/server/world_host.hpp"
#include "turtlegas/turtle/view.hpp"

namespace turtlegas::server {

using json = nlohmann::json;

namespace {

constexpr std::string_view open_example =
    R"({"type": "view_open", "view": {"id": "v1", "center": [250, 200], "size": [500, 400]}})";

/// A ViewError (paths relative to the view object) as the error reply's code, message and field.
[[noreturn]] void refuse(const turtle::ViewError& e, const char* code = "bad_value") {
  const std::string field = "/view" + e.path;
  throw RequestError(code, field + ": " + e.what(), field);
}

}  // namespace

void WorldHost::handle_view_message(ClientState& c, const json& m, const std::string& type) {
  const auto v = m.find("view");
  if (v == m.end()) throw RequestError("missing_field", "/view is missing; send e.g. " + std::string(open_example), "/view");
  json r = ok(m, type.c_str());
  if (type == "view_close") {
    const json* idj = &*v;
    if (v->is_object()) {
      const auto it = v->find("id");
      if (it == v->end()) throw RequestError("missing_field", "/view/id is missing: name the view to close", "/view/id");
      idj = &*it;
    }
    if (!idj->is_string())
      throw RequestError("wrong_type", "/view must be the id of an open view, e.g. {\"type\": \"view_close\", \"view\": \"v1\"}", "/view");
    const std::string id = idj->get<std::string>();
    if (!server_->find_view(id))
      throw RequestError("unknown_view", "/view: no view \"" + id.substr(0, 64) + "\" is open" + open_views_list(), "/view");
    server_->close_view(id);
    r["view"] = id;
    record_view("close", id);
    turtle::View closed;
    closed.id = id;
    note_client_view("close", closed);
  } else {
    if (!v->is_object()) throw RequestError("wrong_type", "/view must be a view object; send e.g. " + std::string(open_example), "/view");
    turtle::View view;
    if (type == "view_open") {
      try {
        view = turtle::parse_view(*v);
      } catch (const turtle::ViewError& e) {
        refuse(e, e.path.empty() && !v->contains("id") ? "missing_field" : "bad_value");
      }
      if (server_->find_view(view.id))
        throw RequestError("refused", "/view/id: a view \"" + view.id.substr(0, 64) + "\" is open already; change it with view_change or choose another id", "/view/id");
    } else {
      const auto idj = v->find("id");
      if (idj == v->end()) throw RequestError("missing_field", "/view/id is missing: name the view to change, e.g. {\"type\": \"view_change\", \"view\": {\"id\": \"v1\", \"size\": [100, 80]}}", "/view/id");
      if (!idj->is_string()) throw RequestError("wrong_type", "/view/id must be a string", "/view/id");
      const auto base = server_->find_view(idj->get<std::string>());
      if (!base)
        throw RequestError("unknown_view", "/view/id: no view \"" + idj->get<std::string>().substr(0, 64) + "\" is open" + open_views_list(), "/view/id");
      try {
        view = turtle::parse_view(*v, &*base);
      } catch (const turtle::ViewError& e) {
        refuse(e);
      }
    }
    if (view.follow && !server_->turtle_index(*view.follow)) {
      std::string known;
      for (const sim::TurtleDef& t : scene_.def.turtles) known += (known.empty() ? "" : ", ") + t.id;
      throw RequestError("unknown_turtle", "/view/follow: no turtle '" + view.follow->substr(0, 64) + "' in this world (turtles: " +
                                               (known.empty() ? "none" : known) + ")", "/view/follow");
    }
    if (type == "view_open") server_->open_view(view);
    else server_->change_view(view);
    r["view"] = turtle::view_to_json(view);
    const char* op = type == "view_open" ? "open" : "change";
    record_view(op, r["view"]);
    note_client_view(op, view);
  }
  reply(c, r);
  // Between steps the event goes out now; during one (a lockstep wait) with the step's events.
  if (!in_step_) fan_out_events();
}

std::string WorldHost::open_views_list() const {
  std::string ids;
  for (const turtle::View& v : server_->views()) ids += (ids.empty() ? "" : ", ") + v.id;
  return " (open: " + (ids.empty() ? std::string("none") : ids) + ")";
}

}  // namespace turtlegas::server
