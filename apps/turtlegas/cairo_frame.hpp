// SPDX-License-Identifier: MIT
// `render`'s painter: a picture of the world (formats::Snapshot) as a PNG through cairo, in the
// look of the SVG snapshot (turtlegas/formats/look.hpp: the same palette, colours, speed scale and
// layout), of a window of the world that may be turned (a view's).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

#include "turtlegas/formats/svg_snapshot.hpp"

namespace turtlegas::apps {

/// The window of the world a picture shows: the rectangle of size w x h centred on (cx, cy),
/// turned by `angle` (radians, Logo convention: the picture's up is that heading).
struct Window {
  double cx = 0.0, cy = 0.0, w = 0.0, h = 0.0, angle = 0.0;
};

/// Draws `snap` as a PNG on `out`: the window `win`, its longer side width_px pixels; `it` the tag
/// game's "it" (ringed in red; "" for none); `layers` what to draw (turtle/view.hpp's kLayer*).
/// Throws std::runtime_error when the PNG cannot be encoded, or written (`out` refused a write:
/// its OutputFile's failure() says why, a full disk say).
void write_png(std::ostream& out, const formats::Snapshot& snap, const Window& win, double width_px,
               const std::string& it, std::uint32_t layers);

}  // namespace turtlegas::apps
