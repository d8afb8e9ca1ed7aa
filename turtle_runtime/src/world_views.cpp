// SPDX-License-Identifier: MIT
// The world server's views (world_server.hpp, "Views") and the Display handle's bodies
// (view.hpp): display data kept beside the physics, changed at control boundaries, logged as
// `view` events.
#include <algorithm>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "server_impl.hpp"

namespace turtlegas::turtle {

using json = nlohmann::json;

// The Display handle: the world server's views (world_server.cpp), changed by the turtle.
void Display::open(const View& v) { agent_->server->self->open_view(v, agent_->id); }
void Display::change(const View& v) { agent_->server->self->change_view(v, agent_->id); }
bool Display::close(const std::string& id) {
  if (!agent_->server->self->find_view(id)) return false;
  agent_->server->self->close_view(id, agent_->id);
  return true;
}
std::optional<View> Display::find(const std::string& id) const { return agent_->server->self->find_view(id); }
std::vector<View> Display::views() const { return agent_->server->self->views(); }

// The world server's views.
namespace {

std::vector<View>::iterator find_in(std::vector<View>& views, const std::string& id) {
  return std::find_if(views.begin(), views.end(), [&](const View& v) { return v.id == id; });
}

}  // namespace

std::optional<std::size_t> WorldServer::turtle_index(const std::string& id) const {
  for (std::size_t i = 0; i < impl_->agents.size(); ++i)
    if (impl_->agents[i]->id == id) return i;
  return std::nullopt;
}

FollowPose WorldServer::follow_pose(std::size_t i) const {
  const sim::TurtleState& s = impl_->world.turtle(i);
  return {s.pos, s.heading};
}

namespace {

void check_view(const WorldServer& server, const View& v) {
  if (v.id.empty()) throw ViewError("/id", "a view needs a non-empty id");
  if (v.follow && !server.turtle_index(*v.follow)) {
    std::string known;
    for (std::size_t i = 0; i < server.turtle_count() && i < 20; ++i)
      known += (i ? ", " : "") + server.turtle_status(i).id;
    throw ViewError("/follow", "follow names no turtle: \"" + v.follow->substr(0, 64) + "\" (turtles: " +
                                   (known.empty() ? std::string("none") : known) + ")");
  }
}

LogEvent view_event(double t, ViewOp op, const View& v, const std::string& by) {
  LogEvent e;
  e.t = t;
  e.kind = "view";
  e.a = v.id;
  e.extra = "\"op\": " + json(std::string(to_string(op))).dump();
  if (!by.empty()) e.extra += ", \"by\": " + json(by).dump(-1, ' ', false, json::error_handler_t::replace);
  if (op != ViewOp::close) e.extra += ", \"view\": " + view_json_text(v);
  return e;
}

}  // namespace

void WorldServer::set_views(std::vector<View> views) {
  for (std::size_t k = 0; k < views.size(); ++k) {
    check_view(*this, views[k]);
    for (std::size_t q = 0; q < k; ++q)
      if (views[q].id == views[k].id) throw ViewError("/id", "duplicate view id \"" + views[k].id + "\"");
  }
  impl_->views = std::move(views);
  ++impl_->views_revision;
}

void WorldServer::set_colours(Colours colours) { impl_->colours = std::move(colours); }

const Colours& WorldServer::colours() const { return impl_->colours; }

void WorldServer::open_view(const View& v, const std::string& by) {
  check_view(*this, v);
  if (find_in(impl_->views, v.id) != impl_->views.end())
    throw ViewError("/id", "a view \"" + v.id + "\" is open already; change it (view_change) or choose another id");
  impl_->views.push_back(v);
  ++impl_->views_revision;
  impl_->emit(view_event(time(), ViewOp::open, v, by));
}

void WorldServer::change_view(const View& v, const std::string& by) {
  check_view(*this, v);
  const auto it = find_in(impl_->views, v.id);
  if (it == impl_->views.end()) throw ViewError("/id", "no view \"" + v.id + "\" is open; open it first");
  *it = v;
  ++impl_->views_revision;
  impl_->emit(view_event(time(), ViewOp::change, v, by));
}

void WorldServer::close_view(const std::string& id, const std::string& by) {
  const auto it = find_in(impl_->views, id);
  if (it == impl_->views.end()) throw ViewError("/id", "no view \"" + id.substr(0, 64) + "\" is open");
  const View v = *it;
  impl_->views.erase(it);
  ++impl_->views_revision;
  impl_->emit(view_event(time(), ViewOp::close, v, by));
}

std::optional<View> WorldServer::find_view(const std::string& id) const {
  const auto it = std::find_if(impl_->views.begin(), impl_->views.end(), [&](const View& v) { return v.id == id; });
  if (it == impl_->views.end()) return std::nullopt;
  return *it;
}

const std::vector<View>& WorldServer::views() const { return impl_->views; }
std::uint64_t WorldServer::views_revision() const { return impl_->views_revision; }

}  // namespace turtlegas::turtle
