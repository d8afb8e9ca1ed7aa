// SPDX-License-Identifier: MIT
// A recording (docs/recording.md, format turtlegas-recording/1): one run as JSON lines,
//   line 1     the header: {"format": "turtlegas-recording/1", "world": {the world as loaded}, ...}
//   then       the event log's lines, exactly as `--events` writes them ({"t": ...});
//              a keyframe line every N events or S simulated seconds ({"keyframe": k, ...}, the
//              full state there, as the state file writes it: numbers shortest round-trip, so the
//              doubles are bit-exact), after the events up to its time;
//   in a served run's recording (`serve --record`), also the inputs the world took from outside
//              as the input log writes them ({"step": ...}: remote turtles' commands, takeovers,
//              walls, spawns, removals, teleports, and clients' views), at the step they were taken;
//   at a clean end  {"index": [...], ...} (each keyframe's time and byte offset) and, last,
//              {"end_of_recording": OFFSET_OF_THE_INDEX_LINE}.
// Written as the run goes and flushed at every keyframe, so a run killed in the middle leaves a
// recording readable up to its last keyframe (read_recording() scans it line by line and says how
// much it recovered).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/formats/event_log.hpp"
#include "turtlegas/formats/names.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/turtle/log_event.hpp"

namespace turtlegas::formats {

inline constexpr const char* recording_format = "turtlegas-recording/1";

/// When keyframes are written: at every multiple of `seconds` of simulated time (the run is cut
/// there), and at the first cut of the run after `events` engine events since the last keyframe.
/// 0 turns either off.
struct KeyframePolicy {
  double seconds = 1.0;
  std::uint64_t events = 100000;
};

/// The header's fields.
struct RecordingHeader {
  std::string world_file;        ///< as given on the command line
  nlohmann::ordered_json world;  ///< the world file as loaded (its keys in the file's order)
  std::string mode;              ///< "exact" or "step"
  double dt = 0.0;               ///< the run's (after --dt)
  std::optional<double> until;   ///< the time the run was asked to reach (none: a served run without --until)
  std::string command;           ///< "run" or "serve"
  KeyframePolicy keyframes;
  /// The controller plugins the world's programs come from: [{"file": ABSOLUTE_PATH,
  /// "controllers": [NAME, ...]}, ...] (null or empty: none); render and replay load them, and
  /// name the one that is missing (docs/recording.md).
  nlohmann::ordered_json plugins;
};

/// Writes a recording as the run goes. Every call appends; keyframe() flushes.
class RecordingWriter {
 public:
  RecordingWriter(std::ostream& out, const RecordingHeader& header);

  /// The engine's events (bare ball worlds), named by `names`.
  template <class Names>
  void events(std::span<const sim::Event> events, const Names& names) {
    buf_.clear();
    for (const sim::Event& e : events) append_event(buf_, event_line(e, names));
    lines_ += events.size();
    put();
  }
  /// The world server's events.
  void events(std::span<const turtle::LogEvent> events);
  /// An input line of a served run (input_log.hpp's, newline-terminated), as it is taken.
  void input(std::string_view line);

  /// Whether a keyframe is due by the events policy, with `engine_events` events taken.
  bool keyframe_due(std::uint64_t engine_events) const;
  /// A keyframe of `world` at its current time; flushes the stream.
  void keyframe(const sim::World& world, const RunNames& names);
  /// The last keyframe's time (one is written by the constructor's caller first).
  double last_keyframe_time() const { return index_.empty() ? 0.0 : index_.back().t; }
  /// The index and the end line; flushes. `stopped`: why the run ended early, empty when it did not.
  void finish(double t, const std::string& stopped);

 private:
  void put();
  std::ostream& out_;
  KeyframePolicy policy_;
  std::string buf_;
  std::uint64_t offset_ = 0;   ///< bytes written
  std::uint64_t lines_ = 0;    ///< event lines written
  std::uint64_t last_events_ = 0;
  std::optional<std::size_t> base_walls_;  ///< the first keyframe's wall count
  struct Entry {
    double t;
    std::uint64_t offset, lines, events;
  };
  std::vector<Entry> index_;
};

/// A keyframe as read back.
struct Keyframe {
  double t = 0.0;
  std::uint64_t events = 0;      ///< the engine's event count there
  std::uint64_t lines = 0;       ///< event lines before it
  std::uint64_t offset = 0;      ///< byte offset of its line
  // Filled by read_keyframe() only (read_recording() leaves them empty, so that a long recording
  // of a big gas costs its index in memory, not its states):
  nlohmann::json state;          ///< the state file's object ({"t", "balls", "turtles"})
  std::uint64_t walls = 0;       ///< walls in the world there (pen-drawn ones added)
  nlohmann::json added_walls;    ///< [[x0, y0, x1, y1], ...]: the walls added since the first keyframe
};

struct Recording {
  RecordingHeader header;
  std::vector<Keyframe> keyframes;  ///< in time order; the first at the run's start
  bool complete = false;            ///< the end line and index were there (the run ended cleanly)
  double end = 0.0;                 ///< the last time the recording vouches for
  std::string stopped;              ///< the run stopped early: why (complete recordings only)
  std::uint64_t bytes = 0;          ///< the file's size
  std::uint64_t dropped_bytes = 0;  ///< an incomplete recording: bytes after its last keyframe
  std::uint64_t dropped_events = 0; ///< an incomplete recording: event lines after its last keyframe
  std::string warning;              ///< non-empty for an incomplete recording: what was recovered
};

/// Reads a recording's header and keyframes: through the index when the file ends with one, by a
/// scan of every line when it does not (a killed run, a cut file), keeping what precedes the last
/// whole keyframe. std::invalid_argument (naming `path`, what is wrong and the fix) for a file that
/// is not a recording, or one without a whole header and first keyframe.
Recording read_recording(const std::string& path);

/// The keyframe at `k.offset`, whole (state and walls filled in).
Keyframe read_keyframe(const std::string& path, const Keyframe& k);

/// Where `world` (re-simulated to the keyframe's time) differs from the keyframe `whole` (as
/// read_keyframe() gives it), in words: the first value that differs, by its place in the state
/// file ("balls/3 'b3' vel: [1, 2] here, [1, 2.5] in the recording"); nothing when they agree bit
/// for bit. A replay or render that re-simulates a recording checks each keyframe with it, so that
/// an altered header world, a program that changed, or another build's different arithmetic is
/// named instead of drawn as if it were the recorded run.
std::optional<std::string> keyframe_difference(const Keyframe& whole, const sim::World& world, const RunNames& names);

/// The input lines ({"step": ...}) of a served run's recording that precede byte `offset` (a
/// keyframe's), as an input log (its header line first) for formats::ReplayInput.
std::string recording_inputs(const std::string& path, std::uint64_t offset, std::string_view world_name, double dt);

/// The event lines of a recording with `lines` at most (a keyframe's `lines`), as `--events` wrote
/// them, newline-terminated.
std::string recording_events(const std::string& path, std::uint64_t lines);

}  // namespace turtlegas::formats
