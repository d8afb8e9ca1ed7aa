// SPDX-License-Identifier: MIT
// The world host: owns the one WorldServer and runs it on the simulation thread (run()), paced
// by the wall clock; every connection's messages come in through one inbox and are handled on
// that thread, at control boundaries or while a lockstep boundary waits for a remote command
// (docs/protocol.md). Nothing a client does can block the simulation except lockstep waiting,
// which --lockstep-timeout bounds. Replies and frames leave as shared immutable buffers through
// Client (client.hpp), whose sends are posted to the I/O threads.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/formats/event_log.hpp"
#include "turtlegas/formats/names.hpp"
#include "turtlegas/formats/recording.hpp"
#include "turtlegas/server/client.hpp"
#include "turtlegas/server/frames.hpp"
#include "turtlegas/server/limits.hpp"
#include "turtlegas/sim/world_def.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/remote.hpp"
#include "turtlegas/turtle/world_server.hpp"
#include "turtlegas/world/scene.hpp"

namespace turtlegas::server {

/// `turtlegas replay` (docs/recording.md): the host plays a recording instead of serving a live
/// world. The world is the recording's, re-simulated (the run is deterministic, so the states are
/// the recorded run's to the bit); time goes from 0 to `end` and back (seek, reverse); nothing a
/// client sends changes the world (claims, commands, walls, save and load are refused).
struct ReplaySource {
  std::string path;           ///< the recording, for messages
  double end = 0.0;           ///< the last time the recording vouches for
  double dt = 0.0;            ///< the recorded run's (after its --dt), for the rebuilt worlds
  bool complete = true;       ///< false: it was cut, and `end` is its last keyframe's time
  std::vector<formats::Keyframe> keyframes;  ///< its index (times and byte offsets; states are read when reached)
  std::string inputs;  ///< a served run's recording: its inputs as an input log (formats::ReplayInput); else empty
};

struct HostOptions {
  std::string world_file;   ///< as given, for messages
  std::string world_text;   ///< GET /api/world
  sim::Mode mode = sim::Mode::exact;
  bool realtime = false;    ///< remote turtles never hold the world up
  double speed = 1.0;       ///< simulated seconds per wall second; 0: as fast as possible
  bool paused = false;
  std::optional<double> until;   ///< stop (as on SIGINT) at this simulated time
  std::string events_path;       ///< the event log; empty: none
  std::string inputs_path;       ///< the input log; empty: none
  std::filesystem::path save_dir;  ///< empty: save and load refused
  std::optional<std::string> token;
  double lockstep_timeout = 10.0;  ///< wall seconds
  std::size_t stack_bytes = 32 * 1024;
  double program_budget = 2.0;
  Limits limits;
  std::optional<ReplaySource> replay;  ///< set: a replay (ReplaySource)
  std::string record_path;             ///< `serve --record`: the recording (docs/recording.md); empty: none
  formats::KeyframePolicy keyframes;   ///< its keyframes
  nlohmann::ordered_json plugins;      ///< its header's plugins (formats::RecordingHeader::plugins)
};

class WorldHost {
 public:
  /// Builds the world from the loaded scene (std::invalid_argument when the runtime refuses it)
  /// and opens the logs (std::runtime_error when a path cannot be written).
  WorldHost(HostOptions options, const turtle::Registry& registry, world::Scene scene);
  ~WorldHost();
  WorldHost(const WorldHost&) = delete;
  WorldHost& operator=(const WorldHost&) = delete;

  // From any thread.
  void connected(std::shared_ptr<Client> client);
  void disconnected(std::shared_ptr<Client> client);
  void post(std::shared_ptr<Client> client, nlohmann::json message);
  /// GET /api/state: `done` gets the state file's text, called on the simulation thread.
  void request_state(std::function<void(std::string)> done);
  void request_stop(std::string reason);
  std::string world_text() const;
  const HostOptions& options() const { return options_; }
  std::size_t clients_open() const { return clients_open_.load(); }
  /// HTTP connections (an HttpSession's life), counted with the clients against --max-clients.
  void http_opened() { ++http_open_; }
  void http_closed() { --http_open_; }
  /// WebSocket, TCP-line and HTTP connections: what --max-clients bounds (docs/protocol.md, "Limits").
  std::size_t connections_open() const { return clients_open_.load() + http_open_.load(); }
  std::uint64_t next_client_id() { return ++last_client_id_; }

  /// The simulation thread's loop: until a stop (a signal, --until, an output that cannot be
  /// written). Returns the exit code: 0, or 1 when an output failed.
  int run();
  /// Called on the simulation thread once the loop has ended and every client was told.
  std::function<void()> on_finished;

 private:
  class Input;
  struct Inbound {
    enum class Kind { message, connect, disconnect, state, stop } kind;
    std::shared_ptr<Client> client;
    nlohmann::json message;
    std::function<void(std::string)> state_done;
    std::string reason;
  };
  struct ClientState {
    std::shared_ptr<Client> client;
    bool hello = false;
    bool authorized = false;
    std::optional<std::string> stream;  ///< FrameStream key when subscribed
    std::uint64_t messages = 0, errors = 0;
    std::size_t claims = 0;
  };
  struct Slot {  ///< a turtle's remote side
    std::uint64_t owner = 0;  ///< the claiming connection, 0 none
    std::optional<turtle::RemoteCommand> queued;
    nlohmann::json queued_id;
    nlohmann::json inflight_id;
    bool busy = false;      ///< a command was accepted and its result has not come
    bool orphan = false;    ///< the command in flight was sent by a connection that let go
    std::uint64_t taken_step = 0;  ///< the boundary of `taken`
    std::size_t taken = 0;         ///< commands taken at that boundary
  };
  struct WallChange {
    std::uint64_t client;
    nlohmann::json id;
    sim::WallDef wall;
  };
  struct BodyChange {  ///< spawn, remove or teleport (host_world_changes.cpp)
    std::uint64_t client = 0;
    nlohmann::json id;
    std::string type;
    std::string body;     ///< the body's id
    bool ball = false;    ///< remove, teleport: the body is a ball
    nlohmann::json spawn;  ///< spawn: {"ball": {...}} or {"turtle": {...}}
    sim::Vec2 pos;
    std::optional<sim::Vec2> vel;
    std::optional<double> heading;
  };
  struct Takeover {
    std::uint64_t client;
    nlohmann::json id;
    std::size_t turtle;
  };
  struct FileRequest {
    std::uint64_t client;
    nlohmann::json id;
    bool load;
    std::string file;
  };

  // The simulation thread's side. The loop, the inbox and the boundary (world_host.cpp, where the
  // order of one turn is written down).
  void drain_inbox();
  bool wait_inbox_until(double steady_deadline);  ///< true when something arrived
  void step_world(double target);
  /// At each control boundary: the inbox, then takeovers, walls and body changes, in that order.
  void at_boundary(turtle::WorldServer& server, std::uint64_t step);
  double now() const;  ///< steady clock, seconds
  void reanchor();
  /// Whether this world, left alone, writes files that grow without bound: a live world (not a
  /// replay) at --speed max with no --until and an event log, input log or recording. It pauses
  /// when its last client leaves.
  bool runs_away_alone() const;

  // The world (host_world.cpp).
  void build_world(world::Scene scene);

  // Dispatch (host_messages.cpp): the message table and the handlers every connection reaches.
  enum class Access;
  struct Handler;
  static std::span<const Handler> handlers();
  void handle(Inbound& in);
  void handle_message(ClientState& c, const nlohmann::json& m);
  void on_hello(ClientState& c, const nlohmann::json& m, const std::string& type);
  void on_ping(ClientState& c, const nlohmann::json& m, const std::string& type);
  void on_stats(ClientState& c, const nlohmann::json& m, const std::string& type);

  // Replies (host_replies.cpp).
  void reply(ClientState& c, const nlohmann::json& message);
  void reply_text(ClientState& c, std::string text);
  void broadcast(const std::string& text);
  void broadcast_status();
  nlohmann::json status_json() const;
  nlohmann::json world_json() const;
  /// Turtle i's touch arcs (names) and range sensors ({name, bearings, range}), as the world
  /// message and the claimed reply give them.
  nlohmann::json sensors_json(std::size_t i) const;
  nlohmann::json senses_json(std::size_t i) const;
  /// The reply to a claim of turtle i granted at time t, control step `step` (docs/protocol.md).
  nlohmann::json claimed_reply(const nlohmann::json& id, std::size_t i, bool takeover, double t, std::uint64_t step) const;
  nlohmann::json ok(const nlohmann::json& m, const char* request) const;
  std::size_t turtle_index(const nlohmann::json& m, const char* example) const;
  void require_live() const;

  // Events and frames (host_frames.cpp).
  void fan_out_events();
  void send_due_frames(double now);
  void end_world(const std::string& reason);
  std::vector<bool> claimed() const;
  FrameClock clock() const;
  void on_subscribe(ClientState& c, const nlohmann::json& m, const std::string& type);
  void on_unsubscribe(ClientState& c, const nlohmann::json& m, const std::string& type);
  void on_snapshot(ClientState& c, const nlohmann::json& m, const std::string& type);

  // Clock controls (host_control.cpp): pause, resume, step, speed, run_until; play, seek, reverse.
  void on_pacing(ClientState& c, const nlohmann::json& m, const std::string& type);
  void on_replay_control(ClientState& c, const nlohmann::json& m, const std::string& type);

  // Remote turtles (host_remote.cpp).
  std::shared_ptr<turtle::InputSource> remote_input();
  void on_claim(ClientState& c, const nlohmann::json& m, const std::string& type);
  void on_release(ClientState& c, const nlohmann::json& m, const std::string& type);
  void on_command(ClientState& c, const nlohmann::json& m, const std::string& type);
  void apply_takeovers(turtle::WorldServer& server, std::uint64_t step);
  /// In lockstep, waits (at most --lockstep-timeout) for the owner's command; meanwhile world
  /// changes and saves are made at this boundary (their senders may be waiting for them before
  /// they send the command), recorded as made while waiting (formats::input_while_waiting).
  std::optional<turtle::RemoteCommand> next_command(std::uint64_t step, std::size_t turtle);
  void on_report(const turtle::RemoteReport& r);
  /// Lets go of every turtle `c` claimed. A command of theirs in flight gets the error `code`
  /// with `why` when `code` is given (its sender would otherwise wait for a result that is not
  /// coming to it), else its result is dropped.
  void release_all(ClientState& c, const char* why, const char* code = nullptr, const std::string& message = {});
  /// Takeovers, walls and spawn/remove/teleport queued, made at this boundary, in that order.
  void apply_changes(turtle::WorldServer& server, std::uint64_t step);
  /// An input-log line, marked when it is made while the world waits for a command (waiting_).
  std::string input_line(std::string line) const;

  // World changes (host_world_changes.cpp): checked on arrival, applied at the boundary.
  void on_add_wall(ClientState& c, const nlohmann::json& m, const std::string& type);
  void apply_wall_changes(turtle::WorldServer& server, std::uint64_t step);
  void queue_body_change(ClientState& c, const nlohmann::json& m, const std::string& type);
  void apply_body_changes(turtle::WorldServer& server, std::uint64_t step);
  void refuse_body_changes(const std::string& reason);

  // Views (host_views.cpp): view_open, view_change, view_close.
  void handle_view_message(ClientState& c, const nlohmann::json& m, const std::string& type);
  std::string open_views_list() const;

  // Files (host_files.cpp): save and load, the input log.
  void on_file(ClientState& c, const nlohmann::json& m, const std::string& type);
  void do_file_requests();
  void write_input(const std::string& line);
  /// What `path` is to the server when it reads or writes it ("the served world", "the live event
  /// log (--events)", ...), else empty: save refuses those.
  std::string in_use(const std::filesystem::path& path) const;
  /// A log or the recording could not be written (errno says why): logged with the option and the
  /// path, the server stops, and run() returns 1.
  void output_failed(const char* option, const std::string& path);
  /// output_failed() for each output stream that has gone bad.
  void check_outputs();

  // A replay's clock (host_recording.cpp).
  void require_not_replay(const std::string& type) const;
  /// A replay to time t: on from now when t is later, else the world rebuilt from its file and
  /// re-simulated from 0 (its events dropped); subscribers get a fresh snapshot after a rebuild.
  void seek(double t);
  /// A replay's next target when it plays, forward or in reverse, and whether it has one.
  bool replay_target(double& target);
  /// A replay's index and header checked against its keyframes before anything is built: a header
  /// dt that is no time step is refused (std::invalid_argument), an end beyond the last keyframe
  /// clamped to it with a warning.
  void check_replay();
  /// replay_run_until(t) in chunks of about 50 ms of wall time; between them a stop (SIGINT,
  /// SIGTERM) is seen and ends the seek there.
  void seek_run_until(double t);
  /// A stop waits in the inbox: stopping_ is set (the rest of the inbox waits for the loop).
  bool stop_requested();

  // `serve --record` and a replay's own inputs and views (host_recording.cpp).
  void start_recording();
  /// run_until(target), cut at the recording's keyframe times, a keyframe written at each.
  void advance(double target);
  /// The last keyframe (when `keyframe`), the index and the end line; closes the recording.
  void finish_recording(const std::string& stopped, bool keyframe = true);
  void record_view(const char* op, const nlohmann::json& view);
  /// A served run's recording replayed: its inputs, read afresh; nullptr otherwise (the host's own).
  std::shared_ptr<turtle::InputSource> world_input();
  /// Spawns `entry` (a protocol or input-log spawn) into `server` and grows the host's scene, ids
  /// and slots with it; returns the new body's index among its kind. `source` names it in errors.
  std::size_t spawn_into_scene(turtle::WorldServer& server, const nlohmann::json& entry, const std::string& source);
  /// A replay: the views its clients opened, opened again after a seek rebuilt the world.
  void reopen_client_views();
  void note_client_view(const char* op, const turtle::View& view);
  std::string state_text() const;
  /// A replay: how many snapshots it may keep (0: none: a world with turtles or a game, whose
  /// programs cannot be copied, or a served run's recording, whose inputs are read as it goes).
  void plan_snapshots();
  /// A replay: run_until(t), stopping on the way at the recording's keyframe times to snapshot
  /// the world (WorldServer::snapshot) while the budget lasts.
  void replay_run_until(double t);
  /// A replay: the recording's keyframes the run has reached and not yet compared, compared with
  /// the run (formats::keyframe_difference); the first difference is warned about once, naming it,
  /// as `render` does: an altered header world, a changed program or another build's arithmetic
  /// would otherwise be shown as if it were the recorded run.
  void check_reached_keyframes();
  /// A replay: the world put back to the latest snapshot at or before t when t is behind the
  /// world or that snapshot is ahead of it; whether it was.
  bool restore_snapshot(double t);

  std::optional<std::ofstream> record_file_;
  std::optional<formats::RecordingWriter> recorder_;
  double next_key_ = 0.0;
  std::vector<turtle::View> client_views_;  ///< a replay's clients' views
  std::map<double, std::shared_ptr<const turtle::WorldServer::Snapshot>> snapshots_;  ///< a replay's, by time
  std::size_t max_snapshots_ = 0;
  std::size_t keys_checked_ = 0;   ///< a replay: its keyframes before this one are compared (or passed)
  bool replay_diverged_ = false;   ///< a replay: a keyframe differed from the run (warned about)

  HostOptions options_;
  const turtle::Registry& registry_;
  world::Scene scene_;
  formats::IdTable ball_ids_;
  std::unique_ptr<turtle::WorldServer> server_;
  std::shared_ptr<turtle::InputSource> input_;  ///< remote turtles' commands and the boundary (host_remote.cpp)
  std::vector<turtle::LogEvent> events_;
  std::optional<std::ofstream> events_file_, inputs_file_;
  std::optional<formats::EventLogWriter> events_writer_;
  std::vector<Slot> slots_;
  std::vector<TurtleLook> looks_;  ///< snapshots' turtle layers and sensor arcs
  std::map<std::uint64_t, ClientState> clients_;
  std::map<std::string, FrameStream> streams_;
  std::deque<WallChange> wall_changes_;
  std::deque<BodyChange> body_changes_;
  std::deque<Takeover> takeovers_;
  std::deque<FileRequest> file_requests_;
  // Pacing.
  bool paused_ = false;
  double speed_ = 1.0;  ///< 0: as fast as possible
  std::optional<double> pause_at_;
  std::uint64_t steps_left_ = 0;  ///< > 0: a `step` request is running
  std::uint64_t step_end_ = 0;    ///< the boundary the running step_world ends on
  double anchor_sim_ = 0.0, anchor_wall_ = 0.0;
  std::optional<std::string> ended_;
  std::string output_error_;  ///< set: an output failed (output_failed)
  std::filesystem::path served_file_;  ///< the world file served (the original, or the last `load`)
  bool stopping_ = false;
  std::string stop_reason_;
  bool in_step_ = false;
  std::optional<std::size_t> waiting_;  ///< the turtle a lockstep boundary waits for (next_command)
  bool reverse_ = false;  ///< a replay plays backwards
  std::uint64_t frames_built_ = 0;
  mutable std::mutex text_mutex_;  // options_.world_text, read by HTTP sessions
  // The inbox.
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Inbound> inbox_;
  std::atomic<bool> inbox_ready_{false};  ///< inbox_ is not empty (read without the lock, to spin on)
  std::atomic<std::size_t> clients_open_{0};
  std::atomic<std::size_t> http_open_{0};
  std::atomic<std::uint64_t> last_client_id_{0};
};

}  // namespace turtlegas::server
