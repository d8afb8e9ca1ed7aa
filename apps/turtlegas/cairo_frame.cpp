// SPDX-License-Identifier: MIT
#include "cairo_frame.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <cairo.h>

#include "turtlegas/formats/look.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/turtle/view.hpp"

namespace turtlegas::apps {
namespace {

namespace look = formats::look;

void set_rgb(cairo_t* cr, const look::Rgb& c, double alpha = 1.0) {
  cairo_set_source_rgba(cr, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0, alpha);
}
void set_grey(cairo_t* cr, int v) { cairo_set_source_rgb(cr, v / 255.0, v / 255.0, v / 255.0); }

/// A stroke `px` pixels wide whatever the world-to-pixel scale.
void stroke_px(cairo_t* cr, double px) {
  cairo_save(cr);
  cairo_identity_matrix(cr);
  cairo_set_line_width(cr, px);
  cairo_stroke(cr);
  cairo_restore(cr);
}

cairo_status_t write_to_stream(void* closure, const unsigned char* data, unsigned int length) {
  auto* out = static_cast<std::ostream*>(closure);
  out->write(reinterpret_cast<const char*>(data), length);
  return *out ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_WRITE_ERROR;
}

}  // namespace

void write_png(std::ostream& out, const formats::Snapshot& snap, const Window& win, double width_px,
               const std::string& it, std::uint32_t layers) {
  const bool walls = layers & turtle::kLayerWalls, balls = layers & turtle::kLayerBalls,
             turtles = layers & turtle::kLayerTurtles, trails = layers & turtle::kLayerTrails,
             roles = layers & turtle::kLayerRoles;
  const bool legend = !snap.balls.empty() && balls;
  const look::Layout l = look::layout_for(win.w, win.h, width_px, legend);
  const double margin = look::margin;
  // Even sides: an mp4 (yuv420p) needs them, and ffmpeg's padding of an odd side was a black row.
  auto even = [](double v) { const int n = static_cast<int>(std::ceil(v)); return n + (n % 2); };
  const int width = even(l.width), height = even(l.height);
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height), cairo_surface_destroy);
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> ctx(cairo_create(surface.get()), cairo_destroy);
  cairo_t* cr = ctx.get();
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);

  // Colours span 0 to the 99th-percentile speed (look.hpp).
  const look::SpeedScale speeds = look::speed_scale(snap.balls);
  const double v_max = speeds.v_max;

  // The title.
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 16);
  set_grey(cr, 0);
  char title[512];
  std::snprintf(title, sizeof title, "%s - t = %.6g s, %zu balls", snap.title.c_str(), snap.time, snap.balls.size());
  std::string text = title;
  if (!snap.turtles.empty())
    text += ", " + std::to_string(snap.turtles.size()) + (snap.turtles.size() == 1 ? " turtle" : " turtles");
  // A title wider than the picture is set smaller until it fits (it was cut at the right edge).
  cairo_text_extents_t ext;
  cairo_text_extents(cr, text.c_str(), &ext);
  const double room = width - 2 * margin;
  if (ext.x_advance > room && ext.x_advance > 0.0) cairo_set_font_size(cr, std::max(6.0, 16.0 * room / ext.x_advance));
  cairo_move_to(cr, margin, margin + 14);
  cairo_show_text(cr, text.c_str());

  // The world inside the window: +y up, clipped to the window's rectangle.
  cairo_save(cr);
  cairo_rectangle(cr, margin, l.top, win.w * l.scale, win.h * l.scale);
  cairo_clip(cr);
  cairo_translate(cr, margin + win.w * l.scale / 2, l.top + win.h * l.scale / 2);
  cairo_scale(cr, l.scale, -l.scale);
  cairo_rotate(cr, win.angle);  // a heading of `angle` points up
  cairo_translate(cr, -win.cx, -win.cy);

  cairo_rectangle(cr, 0, 0, snap.arena.width, snap.arena.height);
  cairo_set_source_rgb(cr, 0xf7 / 255.0, 0xf7 / 255.0, 0xf7 / 255.0);
  cairo_fill_preserve(cr);
  set_grey(cr, 0x99);
  stroke_px(cr, 1);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  for (const auto& wall : snap.walls) {
    if (!walls) break;
    const sim::WallKey pose = sim::wall_pose(wall, snap.time);
    const bool there = sim::wall_visible(wall, snap.time);
    cairo_move_to(cr, pose.from.x, pose.from.y);
    cairo_line_to(cr, pose.to.x, pose.to.y);
    if (there && look::passable_by_some(wall, snap.turtles)) {  // some turtle passes through it
      set_rgb(cr, look::wall_passable_colour);
      const double dash[2] = {6, 3};
      cairo_set_dash(cr, dash, 2, 0);
    } else if (there) {
      set_grey(cr, 0x22);
    } else {
      set_grey(cr, 0xbb);
      const double dash[2] = {4, 3};
      cairo_set_dash(cr, dash, 2, 0);
    }
    stroke_px(cr, 2);
    cairo_set_dash(cr, nullptr, 0, 0);
  }
  for (std::size_t i = 0; i < snap.balls.size() && balls; ++i) {
    const auto& b = snap.balls[i];
    cairo_arc(cr, b.pos.x, b.pos.y, b.radius, 0, 2 * M_PI);
    set_rgb(cr, look::speed_colour(speeds.at(i)));
    cairo_fill(cr);
  }
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  for (std::size_t i = 0; i < snap.turtles.size(); ++i) {
    const auto& t = snap.turtles[i];
    if (t.trail.size() < 2 || !trails) continue;
    bool gap = true;  // a break between strokes (the pen lifted, or a teleport)
    for (const sim::Vec2 p : t.trail) {
      if (turtle::is_trail_break(p)) {
        gap = true;
        continue;
      }
      if (gap) cairo_move_to(cr, p.x, p.y);
      else cairo_line_to(cr, p.x, p.y);
      gap = false;
    }
    set_rgb(cr, look::turtle_colour(i));
    stroke_px(cr, 1.5);
  }
  for (std::size_t i = 0; i < snap.turtles.size() && turtles; ++i) {
    const auto& t = snap.turtles[i];
    if (t.id == it && roles) {  // the tag game's "it": a red ring around it
      cairo_arc(cr, t.pos.x, t.pos.y, t.radius * 1.6, 0, 2 * M_PI);
      cairo_set_source_rgb(cr, 0.85, 0.1, 0.1);
      stroke_px(cr, 3);
    }
    cairo_arc(cr, t.pos.x, t.pos.y, t.radius, 0, 2 * M_PI);
    set_rgb(cr, look::turtle_colour(i), 0.8);
    cairo_fill_preserve(cr);
    set_grey(cr, 0x22);
    stroke_px(cr, 1);
    const sim::Vec2 tip = t.pos + t.radius * sim::heading_unit(t.heading);
    cairo_move_to(cr, t.pos.x, t.pos.y);
    cairo_line_to(cr, tip.x, tip.y);
    stroke_px(cr, 2);
    if (t.fault) {
      const double d = t.radius * 0.7;
      cairo_move_to(cr, t.pos.x - d, t.pos.y - d);
      cairo_line_to(cr, t.pos.x + d, t.pos.y + d);
      cairo_move_to(cr, t.pos.x - d, t.pos.y + d);
      cairo_line_to(cr, t.pos.x + d, t.pos.y - d);
      cairo_set_source_rgb(cr, 0.8, 0, 0);
      stroke_px(cr, 2);
    }
  }
  // Where each turtle is in the picture's pixels (labels are drawn there, outside the clip).
  std::vector<std::pair<double, double>> at(snap.turtles.size());
  for (std::size_t i = 0; i < snap.turtles.size(); ++i) {
    at[i] = {snap.turtles[i].pos.x, snap.turtles[i].pos.y};
    cairo_user_to_device(cr, &at[i].first, &at[i].second);
  }
  cairo_restore(cr);

  // Ids beside each turtle's upper right, upright; to its left or below where they would leave
  // the picture (look::label_spot). Turtles outside the window get none.
  cairo_set_font_size(cr, 11);
  set_grey(cr, 0);
  for (std::size_t i = 0; i < snap.turtles.size() && turtles; ++i) {
    const auto& t = snap.turtles[i];
    const auto [px, py] = at[i];
    if (px < margin || px > margin + win.w * l.scale || py < l.top || py > l.top + win.h * l.scale) continue;
    cairo_text_extents_t te;
    cairo_text_extents(cr, t.id.c_str(), &te);
    const look::LabelSpot spot = look::label_spot(px, py, t.radius * l.scale, te.x_advance, 11.0, width, height);
    cairo_move_to(cr, spot.x, spot.y);
    cairo_show_text(cr, t.id.c_str());
  }

  // The legend: a colour bar from 0 (bottom) to v_max (top), when there are balls.
  if (legend) {
    const double lx = l.legend_x, ly = l.legend_y, lh = look::legend_h;
    cairo_pattern_t* g = cairo_pattern_create_linear(0, ly + lh, 0, ly);
    for (std::size_t k = 0; k < look::palette.size(); ++k) {
      const double u = static_cast<double>(k) / (look::palette.size() - 1);
      const look::Rgb c = look::speed_colour(u);
      cairo_pattern_add_color_stop_rgb(g, u, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
    }
    cairo_rectangle(cr, lx, ly, look::legend_bar_w, lh);
    cairo_set_source(cr, g);
    cairo_fill_preserve(cr);
    cairo_pattern_destroy(g);
    set_grey(cr, 0x99);
    cairo_set_line_width(cr, 1);
    cairo_stroke(cr);
    set_grey(cr, 0);
    cairo_set_font_size(cr, 12);
    cairo_move_to(cr, lx - 8, ly - 6);
    cairo_show_text(cr, "speed");
    cairo_set_font_size(cr, 11);
    char vmax[64];
    std::snprintf(vmax, sizeof vmax, ">= %.6g", v_max);
    cairo_move_to(cr, lx + 18, ly + 10);
    cairo_show_text(cr, vmax);
    cairo_move_to(cr, lx + 18, ly + lh);
    cairo_show_text(cr, "0");
  }
  cairo_surface_flush(surface.get());
  if (cairo_surface_write_to_png_stream(surface.get(), write_to_stream, &out) != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error(!out ? "could not write the PNG" : "could not encode the PNG");  // the stream says why
}

}  // namespace turtlegas::apps
