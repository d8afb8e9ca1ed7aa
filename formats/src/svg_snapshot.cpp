// SPDX-License-Identifier: MIT
#include "turtlegas/formats/svg_snapshot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <ostream>

#include "turtlegas/formats/look.hpp"
#include "turtlegas/sim/angles.hpp"

namespace turtlegas::formats {
namespace {

/// Six significant digits: a pixel is far coarser, and the file stays small.
std::string fmt(double v) {
  std::array<char, 32> buf{};
  std::snprintf(buf.data(), buf.size(), "%.6g", v);
  return buf.data();
}

std::string xml_escape(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace

Snapshot snapshot_of(const sim::WorldDef& def) {
  Snapshot s;
  s.title = def.name;
  s.arena = def.arena;
  s.walls = def.walls;
  if (def.arena.boundary == sim::Boundary::walls)
    for (auto& w : sim::arena_walls(def.arena)) s.walls.push_back(std::move(w));
  s.balls.reserve(def.balls.size());
  for (const auto& b : def.balls) s.balls.push_back({b.pos, b.vel, b.radius});
  for (const auto& t : def.turtles) s.turtles.push_back({t.id, t.pos, t.heading, t.radius, {}, false, t.layers});
  return s;
}

Snapshot snapshot_of(const turtle::WorldServer& server, const sim::WorldDef& def) {
  Snapshot s = snapshot_of(server.world(), def);
  for (std::size_t i = 0; i < s.turtles.size() && i < server.turtle_count(); ++i) {
    turtle::WorldServer::TurtleInfo info = server.turtle(i);
    s.turtles[i].trail = std::move(info.trail);
    s.turtles[i].fault = !info.fault.empty();
  }
  return s;
}

void write_svg(std::ostream& out, const Snapshot& snap, double width_px) {
  const double aw = snap.arena.width, ah = snap.arena.height;
  const look::Layout layout = look::layout_for(aw, ah, width_px, !snap.balls.empty());
  const double scale = layout.scale, margin = look::margin, w = layout.width, h = layout.height, top = layout.top;

  // Colours span 0 to the 99th-percentile speed (look.hpp).
  const look::SpeedScale speeds = look::speed_scale(snap.balls);
  const double v_max = speeds.v_max;

  const std::string title = xml_escape(snap.title.empty() ? std::string("turtlegas") : snap.title);
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << fmt(w) << "\" height=\"" << fmt(h)
      << "\" viewBox=\"0 0 " << fmt(w) << ' ' << fmt(h) << "\" font-family=\"sans-serif\">\n"
      << "<title>" << title << " at t = " << fmt(snap.time) << " s</title>\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      << "<text x=\"" << fmt(margin) << "\" y=\"" << fmt(margin + 14) << "\" font-size=\"16\">" << title
      << " — t = " << fmt(snap.time) << " s, " << snap.balls.size() << " balls";
  if (!snap.turtles.empty()) out << ", " << snap.turtles.size() << " turtle" << (snap.turtles.size() == 1 ? "" : "s");
  out << "</text>\n";

  // World coordinates inside the group: +y up, one world unit = scale pixels.
  out << "<g transform=\"translate(" << fmt(margin) << ' ' << fmt(top + ah * scale) << ") scale(" << fmt(scale)
      << ' ' << fmt(-scale) << ")\">\n"
      << "<rect x=\"0\" y=\"0\" width=\"" << fmt(aw) << "\" height=\"" << fmt(ah)
      << "\" fill=\"#f7f7f7\" stroke=\"#999\" stroke-width=\"1\" vector-effect=\"non-scaling-stroke\"/>\n";
  // Moving walls where they are at the snapshot's time; walls not there just now dashed and pale.
  for (const auto& wall : snap.walls) {
    const sim::WallKey pose = sim::wall_pose(wall, snap.time);
    const bool there = sim::wall_visible(wall, snap.time);
    const bool passable = look::passable_by_some(wall, snap.turtles);
    out << "<line" << (passable ? " class=\"wall-passable\"" : "") << " x1=\"" << fmt(pose.from.x) << "\" y1=\"" << fmt(pose.from.y)
        << "\" x2=\"" << fmt(pose.to.x) << "\" y2=\"" << fmt(pose.to.y)
        << (!there      ? "\" stroke=\"#bbb\" stroke-dasharray=\"4 3\""
            : passable ? "\" stroke=\"" + look::hex(look::wall_passable_colour) + "\" stroke-dasharray=\"6 3\""
                       : std::string("\" stroke=\"#222\""))
        << " stroke-width=\"2\" stroke-linecap=\"round\" vector-effect=\"non-scaling-stroke\"/>\n";
  }
  for (const auto& trail : snap.ball_trails) {
    if (trail.size() < 2) continue;
    out << "<polyline class=\"ball-trail\" fill=\"none\" stroke=\"#8a8fa8\" stroke-opacity=\"0.7\" "
           "stroke-width=\"0.8\" stroke-linejoin=\"round\" vector-effect=\"non-scaling-stroke\" points=\"";
    for (std::size_t k = 0; k < trail.size(); ++k) out << (k == 0 ? "" : " ") << fmt(trail[k].x) << ',' << fmt(trail[k].y);
    out << "\"/>\n";
  }
  for (std::size_t i = 0; i < snap.balls.size(); ++i) {
    const auto& b = snap.balls[i];
    out << "<circle cx=\"" << fmt(b.pos.x) << "\" cy=\"" << fmt(b.pos.y) << "\" r=\"" << fmt(b.radius)
        << "\" fill=\"" << look::hex(look::speed_colour(speeds.at(i))) << "\"/>\n";
  }
  // Trails under the turtles, so a turtle is never hidden by its own path.
  for (std::size_t i = 0; i < snap.turtles.size(); ++i) {
    const auto& t = snap.turtles[i];
    // One polyline per stroke: a break (the pen lifted, or a teleport) draws nothing across it.
    for (std::size_t from = 0; from < t.trail.size();) {
      std::size_t to = from;
      while (to < t.trail.size() && !turtle::is_trail_break(t.trail[to])) ++to;
      if (to - from >= 2) {
        out << "<polyline class=\"trail\" fill=\"none\" stroke=\"" << look::hex(look::turtle_colour(i))
            << "\" stroke-width=\"1.5\" stroke-linejoin=\"round\" vector-effect=\"non-scaling-stroke\" points=\"";
        for (std::size_t k = from; k < to; ++k) out << (k == from ? "" : " ") << fmt(t.trail[k].x) << ',' << fmt(t.trail[k].y);
        out << "\"/>\n";
      }
      from = to + 1;
    }
  }
  for (std::size_t i = 0; i < snap.turtles.size(); ++i) {
    const auto& t = snap.turtles[i];
    const sim::Vec2 tip = t.pos + t.radius * sim::heading_unit(t.heading);
    out << "<circle class=\"turtle\" cx=\"" << fmt(t.pos.x) << "\" cy=\"" << fmt(t.pos.y) << "\" r=\"" << fmt(t.radius)
        << "\" fill=\"" << look::hex(look::turtle_colour(i))
        << "\" fill-opacity=\"0.8\" stroke=\"#222\" stroke-width=\"1\" vector-effect=\"non-scaling-stroke\"/>\n"
        << "<line class=\"heading\" x1=\"" << fmt(t.pos.x) << "\" y1=\"" << fmt(t.pos.y) << "\" x2=\"" << fmt(tip.x)
        << "\" y2=\"" << fmt(tip.y)
        << "\" stroke=\"#222\" stroke-width=\"2\" stroke-linecap=\"round\" vector-effect=\"non-scaling-stroke\"/>\n";
    if (t.fault) {
      const double d = t.radius * 0.7;
      out << "<path class=\"fault\" d=\"M" << fmt(t.pos.x - d) << ',' << fmt(t.pos.y - d) << " L" << fmt(t.pos.x + d)
          << ',' << fmt(t.pos.y + d) << " M" << fmt(t.pos.x - d) << ',' << fmt(t.pos.y + d) << " L" << fmt(t.pos.x + d)
          << ',' << fmt(t.pos.y - d)
          << "\" stroke=\"#c00\" stroke-width=\"2\" vector-effect=\"non-scaling-stroke\"/>\n";
    }
  }
  out << "</g>\n";
  // Labels in pixel coordinates (outside the flipped group, so the text is upright), beside each
  // turtle's upper right.
  // A label that would leave the picture goes to the turtle's left (or below it) instead (look.hpp);
  // its width is estimated at 0.62 em a character, a little over sans-serif's average.
  for (const auto& t : snap.turtles) {
    const double text_w = 11.0 * 0.62 * static_cast<double>(t.id.size());
    const look::LabelSpot spot = look::label_spot(margin + t.pos.x * scale, top + (ah - t.pos.y) * scale, t.radius * scale,
                                                  text_w, 11.0, w, h);
    out << "<text class=\"turtle-id\" x=\"" << fmt(spot.x) << "\" y=\"" << fmt(spot.y) << "\" font-size=\"11\">"
        << xml_escape(t.id) << "</text>\n";
  }

  // Legend: a vertical colour bar from 0 (bottom) to v_max (top); only when there are balls.
  if (snap.balls.empty()) {
    out << "</svg>\n";
    return;
  }
  const double lx = layout.legend_x, ly = layout.legend_y, lh = look::legend_h;
  out << "<defs><linearGradient id=\"speed\" x1=\"0\" y1=\"1\" x2=\"0\" y2=\"0\">";
  for (std::size_t k = 0; k < look::palette.size(); ++k) {
    const double u = static_cast<double>(k) / (look::palette.size() - 1);
    out << "<stop offset=\"" << fmt(u) << "\" stop-color=\"" << look::hex(look::speed_colour(u)) << "\"/>";
  }
  out << "</linearGradient></defs>\n"
      << "<text x=\"" << fmt(lx - 8) << "\" y=\"" << fmt(ly - 6) << "\" font-size=\"12\">speed</text>\n"
      << "<rect x=\"" << fmt(lx) << "\" y=\"" << fmt(ly) << "\" width=\"" << fmt(look::legend_bar_w) << "\" height=\"" << fmt(lh)
      << "\" fill=\"url(#speed)\" stroke=\"#999\"/>\n"
      << "<text x=\"" << fmt(lx + 18) << "\" y=\"" << fmt(ly + 10) << "\" font-size=\"11\">&#8805; " << fmt(v_max)
      << "</text>\n"
      << "<text x=\"" << fmt(lx + 18) << "\" y=\"" << fmt(ly + lh) << "\" font-size=\"11\">0</text>\n"
      << "</svg>\n";
}

}  // namespace turtlegas::formats
