// SPDX-License-Identifier: MIT
// The look of a picture of the world: one palette, one set of turtle colours, one speed scale and
// one layout, shared by the SVG snapshot (svg_snapshot.cpp) and `render`'s PNG pictures and frames
// (apps/turtlegas/cairo_frame.cpp), so that the two cannot drift apart.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "turtlegas/sim/vec2.hpp"

namespace turtlegas::formats::look {

/// A colour, 0-255 per channel.
using Rgb = std::array<int, 3>;

/// Balls by speed: viridis at five stops, perceptually even and readable in grey.
inline constexpr std::array<Rgb, 5> palette = {{{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}};

/// Turtles and their trails: Tableau 10, distinct hues that stand out from the viridis balls.
inline constexpr std::array<Rgb, 10> turtle_colours = {{{0x4e, 0x79, 0xa7}, {0xf2, 0x8e, 0x2b}, {0xe1, 0x57, 0x59},
                                                        {0x76, 0xb7, 0xb2}, {0x59, 0xa1, 0x4f}, {0xed, 0xc9, 0x48},
                                                        {0xb0, 0x7a, 0xa1}, {0xff, 0x9d, 0xa7}, {0x9c, 0x75, 0x5f},
                                                        {0xba, 0xb0, 0xac}}};

/// Turtle i's colour (the colours repeat after ten turtles).
inline const Rgb& turtle_colour(std::size_t i) { return turtle_colours[i % turtle_colours.size()]; }

/// The palette at u in [0, 1] (clamped), interpolated between its stops and rounded per channel.
Rgb speed_colour(double u);

/// "#4e79a7".
std::string hex(const Rgb& c);

/// The balls' speeds and the speed the palette's top stands for: the 99th percentile, so that one
/// fast outlier does not wash out the rest.
struct SpeedScale {
  std::vector<double> speeds;  ///< per ball, world units per second
  double v_max = 0.0;          ///< the 99th-percentile speed (0 with no balls or none moving)
  double scale = 1.0;          ///< v_max, or 1 when it is 0
  /// Ball i's place on the palette, 0 to 1 (above 1 for the fastest per cent: clamped).
  double at(std::size_t i) const { return speeds[i] / scale; }
};
/// The scale of these speeds.
SpeedScale scale_of_speeds(std::vector<double> speeds);
/// The scale of discs' speeds (anything with a `vel`: Snapshot::balls).
template <class Discs>
SpeedScale speed_scale(const Discs& discs) {
  std::vector<double> speeds;
  speeds.reserve(discs.size());
  for (const auto& d : discs) speeds.push_back(sim::norm(d.vel));
  return scale_of_speeds(std::move(speeds));
}

/// Margins, the title line and the legend column, in pixels.
inline constexpr double margin = 12.0, title_h = 30.0, legend_w = 90.0, min_world_h = 160.0;
inline constexpr double legend_dx = 24.0, legend_dy = 16.0, legend_h = 120.0, legend_bar_w = 14.0;

/// The layout of a picture of a window w x h world units wide and high whose longer side is
/// width_px pixels: the world below the title, and the legend column on its right when there is a
/// legend to draw (balls coloured by speed); without one the picture ends a margin past the world.
struct Layout {
  double scale = 1.0;   ///< pixels per world unit
  double top = 0.0;     ///< the world's top edge, pixels
  double width = 0.0;   ///< the picture's, pixels (not rounded)
  double height = 0.0;
  double legend_x = 0.0, legend_y = 0.0;  ///< the colour bar's top left
};
Layout layout_for(double w, double h, double width_px, bool legend = true);

/// Where a label `text_w` x `text_h` pixels goes beside a disc at pixel (cx, cy) of pixel radius
/// r: its baseline's left end, at the disc's upper right, or flipped to its left and below it
/// where it would leave the picture (width x height pixels); never outside it when it fits.
struct LabelSpot {
  double x = 0.0, y = 0.0;
};
LabelSpot label_spot(double cx, double cy, double r, double text_w, double text_h, double width, double height);

/// Whether some turtle passes through this wall (its collision layers do not meet the wall's; a
/// builder's own pen walls, say): such walls are drawn dashed in wall_passable_colour.
template <class Wall, class Turtles>
bool passable_by_some(const Wall& wall, const Turtles& turtles) {
  for (const auto& t : turtles)
    if (!wall.layers.collides_with(t.layers)) return true;
  return false;
}
inline constexpr Rgb wall_passable_colour = {0x4e, 0x79, 0xa7};

}  // namespace turtlegas::formats::look
