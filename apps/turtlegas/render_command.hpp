// SPDX-License-Identifier: MIT
// `turtlegas render WORLD.json|R.tgrec --at T --out F.svg|F.png` and `--frames DIR --fps 30 --from
// T0 --to T1 [--video F.mp4]`: pictures and videos without a browser (docs/recording.md,
// "Render"). The scene is simulated (a recording's world re-simulated) to each time and drawn as
// the SVG snapshot draws it; PNGs through cairo, videos through ffmpeg when it is installed.
#pragma once

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "run_loop.hpp"
#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

struct RenderOptions {
  std::string input;               ///< a world file or a recording
  std::optional<double> at;        ///< one picture at this time
  std::string out;                 ///< its file: .svg or .png
  std::string frames;              ///< a directory for frame-00000.png, ...
  std::string video;               ///< an .mp4 (through ffmpeg)
  double fps = 30.0;
  std::optional<double> from, to;  ///< the frames' span (default: 0 to the recording's end)
  double width = 800.0;            ///< pixels across the arena's longer side
  std::string view;                ///< a view id (the world's "views")
  LimitOptions limits;             ///< --max-wall-seconds, --max-events
  bool program_logs = false;       ///< print the programs' Turtle::log lines again (the recorded run printed them)
};

CLI::App* add_render_command(CLI::App& app, RenderOptions& opt);
/// Draws what `opt` asks for: exit_ok, or exit_limit or 128 + a signal when it stopped early (the
/// frames drawn before it are whole; a stopped --at or --video is not written).
int render_command(const RenderOptions& opt, const turtle::Registry& registry);

}  // namespace turtlegas::apps
