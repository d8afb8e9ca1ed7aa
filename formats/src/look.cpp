// SPDX-License-Identifier: MIT
#include "turtlegas/formats/look.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace turtlegas::formats::look {

Rgb speed_colour(double u) {
  u = std::clamp(u, 0.0, 1.0) * (palette.size() - 1);
  const auto k = std::min(static_cast<std::size_t>(u), palette.size() - 2);
  const double f = u - static_cast<double>(k);
  Rgb rgb{};
  for (int c = 0; c < 3; ++c) rgb[c] = static_cast<int>(std::lround(palette[k][c] + f * (palette[k + 1][c] - palette[k][c])));
  return rgb;
}

std::string hex(const Rgb& c) {
  std::array<char, 8> buf{};
  std::snprintf(buf.data(), buf.size(), "#%02x%02x%02x", c[0], c[1], c[2]);
  return buf.data();
}

SpeedScale scale_of_speeds(std::vector<double> speeds) {
  SpeedScale s;
  s.speeds = std::move(speeds);
  if (!s.speeds.empty()) {
    const auto k = static_cast<std::ptrdiff_t>((s.speeds.size() - 1) * 99 / 100);
    std::vector<double> sorted = s.speeds;
    std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
    s.v_max = sorted[static_cast<std::size_t>(k)];
  }
  s.scale = s.v_max > 0.0 ? s.v_max : 1.0;
  return s;
}

Layout layout_for(double w, double h, double width_px, bool legend) {
  Layout l;
  l.scale = width_px / std::max(w, h);
  l.top = title_h + margin;
  l.width = w * l.scale + 2 * margin + (legend ? legend_w : 0.0);
  l.height = std::max(h * l.scale, min_world_h) + title_h + 2 * margin;
  l.legend_x = margin + w * l.scale + legend_dx;
  l.legend_y = l.top + legend_dy;
  return l;
}

LabelSpot label_spot(double cx, double cy, double r, double text_w, double text_h, double width, double height) {
  constexpr double gap = 2.0;
  LabelSpot s{cx + r + gap, cy - r};
  if (s.x + text_w > width - gap) s.x = cx - r - gap - text_w;  // off the right edge: on the left
  if (s.y - text_h < gap) s.y = cy + r + text_h;                 // off the top: below
  s.x = std::clamp(s.x, gap, std::max(gap, width - gap - text_w));
  s.y = std::clamp(s.y, text_h + gap, std::max(text_h + gap, height - gap));
  return s;
}

}  // namespace turtlegas::formats::look
