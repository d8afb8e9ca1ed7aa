// SPDX-License-Identifier: MIT
// Snapshots and frames (docs/protocol.md, "The snapshot", "The frame", "Binary frames"): built
// on the simulation thread from the WorldServer's public accessors, once per subscription kind,
// and handed to every subscriber of that kind as one immutable buffer.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/formats/names.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::server {

/// What a subscription asked for; subscriptions with the same kind share their frames.
struct FrameKind {
  double rate = 30.0;     ///< frames per wall-clock second
  bool binary = false;
  bool all_events = false;
  std::vector<std::string> events;  ///< sorted, when not all_events
  bool velocities = true;
  /// Only the balls whose centres lie in [x0, x1] x [y0, y1] (docs/protocol.md, "region").
  std::optional<std::array<double, 4>> region;
  std::string key() const;
  bool wants(std::string_view event_kind) const;
};

/// The pacing fields every frame and snapshot carries.
struct FrameClock {
  double wall = 0.0;  ///< Unix seconds
  bool paused = false;
  nlohmann::json speed;  ///< a number or "max"
};

/// What a snapshot says of each turtle beyond its state: its collision layers as the world runs
/// them (builders in their own category) and its sensor arcs, for the viewer.
struct TurtleLook {
  sim::Layers layers;
  std::vector<turtle::SensorArc> sensors;
};

/// The snapshot message; `id` echoed when not null. `claimed[i]`: turtle i is claimed; `arena`
/// the arena's JSON object ({"width", "height", "boundary"}); `looks[i]` turtle i's.
std::string snapshot_text(const turtle::WorldServer& server, const formats::IdTable& ball_ids,
                          const std::vector<bool>& claimed, const FrameClock& clock, const nlohmann::json& id,
                          const nlohmann::json& arena, const std::vector<TurtleLook>& looks);

/// The open views as a JSON array of view objects (turtle/view.hpp), in opening order.
nlohmann::json views_json(const turtle::WorldServer& server);
/// The same as JSON text (turtle::view_json_text), for snapshots and frames.
std::string views_text(const turtle::WorldServer& server);

/// The frames of one subscription kind.
class FrameStream {
 public:
  FrameStream(FrameKind kind, const turtle::WorldServer& server);
  const FrameKind& kind() const { return kind_; }
  /// One event-log line (JSON object text without newline) of kind `event_kind`, if wanted.
  void add_event(std::string_view event_kind, std::string_view line, std::size_t max_events);
  /// The next frame: state now, and what is new since the previous one.
  std::shared_ptr<const std::string> build(const turtle::WorldServer& server, const std::vector<bool>& claimed,
                                           const FrameClock& clock);
  double next_due = 0.0;  ///< steady-clock seconds at which the next frame is due
  std::uint64_t built = 0;

 private:
  FrameKind kind_;
  std::vector<std::size_t> trail_sent_;
  std::size_t walls_sent_ = 0;
  std::uint64_t views_sent_ = 0;  ///< the views_revision() the last frame carried
  std::string events_;
  std::size_t event_count_ = 0, events_dropped_ = 0;
};

}  // namespace turtlegas::server
