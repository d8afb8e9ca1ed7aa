// SPDX-License-Identifier: MIT
// The simulation side of `turtlegas serve`: the one WorldServer, its inbox applied at control
// boundaries, pacing, frames, remote turtles, files. Over 600 lines because handle_message
// dispatches every protocol message (about 275 lines, one case per message type, each validating
// and answering as docs/protocol.md says); it is the first thing to move into per-message handlers
// when the protocol grows (the viewer's view_* messages would be the moment).
#include "turtlegas/server/world_host.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <utility>

#include <spdlog/spdlog.h>

#include "turtlegas/formats/input_log.hpp"
#include "turtlegas/formats/json_text.hpp"
#include "turtlegas/formats/state_file.hpp"
#include "turtlegas/server/protocol.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/world/file_error.hpp"
#include "turtlegas/world/world_file.hpp"

namespace turtlegas::server {
namespace {

using nlohmann::json;

std::string dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

bool is_command(const std::string& type) {
  return type == "forward" || type == "back" || type == "left" || type == "right" || type == "wait" ||
         type == "yield" || type == "pen";
}

/// The lockstep wait ran out: ends the world (docs/protocol.md, "Lockstep and real time").
struct LockstepTimeout : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string fmt(double v) {
  std::string s;
  formats::append_number(s, v);
  return s;
}

}  // namespace

class WorldHost::Input : public turtle::InputSource {
 public:
  explicit Input(WorldHost& host) : host_(host) {}
  void at_boundary(turtle::WorldServer& server, std::uint64_t step) override { host_.at_boundary(server, step); }
  std::optional<turtle::RemoteCommand> next(std::uint64_t step, std::size_t turtle) override {
    return host_.next_command(step, turtle);
  }

 private:
  WorldHost& host_;
};

WorldHost::WorldHost(HostOptions options, const turtle::Registry& registry, world::Scene scene)
    : options_(std::move(options)), registry_(registry) {
  paused_ = options_.paused;
  speed_ = options_.speed;
  input_ = std::make_shared<Input>(*this);
  if (!options_.events_path.empty()) {
    events_file_.emplace(options_.events_path, std::ios::binary | std::ios::trunc);
    if (!*events_file_) throw std::runtime_error("--events: cannot write '" + options_.events_path + "'");
    events_writer_.emplace(*events_file_);
  }
  if (!options_.inputs_path.empty()) {
    inputs_file_.emplace(options_.inputs_path, std::ios::binary | std::ios::trunc);
    if (!*inputs_file_) throw std::runtime_error("--inputs-out: cannot write '" + options_.inputs_path + "'");
    *inputs_file_ << formats::input_header_line(scene.def.name, scene.def.dt);
  }
  build_world(std::move(scene));
  start_recording();
  plan_snapshots();
}

WorldHost::~WorldHost() = default;

void WorldHost::build_world(world::Scene scene) {
  scene_ = std::move(scene);
  ball_ids_ = formats::ball_ids(scene_.def);
  turtle::ServerOptions o;
  o.mode = options_.mode;
  o.stack_bytes = options_.stack_bytes;
  o.program_budget = options_.program_budget;
  o.input = world_input();
  if (!o.input) o.input = input_;
  o.remote_reports = [this](const turtle::RemoteReport& r) { on_report(r); };
  server_.reset();
  server_ = world::make_server(scene_, registry_, o);
  server_->set_event_log(&events_);
  slots_.assign(server_->turtle_count(), Slot{});
  looks_.clear();
  const sim::WorldDef layered = turtle::with_builder_layers(scene_.def, scene_.programs);
  for (std::size_t i = 0; i < layered.turtles.size(); ++i) looks_.push_back({layered.turtles[i].layers, scene_.programs[i].sensors});
  wall_changes_.clear();
  body_changes_.clear();
  takeovers_.clear();
  ended_.reset();
  pause_at_.reset();
  steps_left_ = 0;
  reanchor();
}

std::string WorldHost::world_text() const {
  std::lock_guard lock(text_mutex_);
  return options_.world_text;
}

// ---- from any thread --------------------------------------------------------------------------

void WorldHost::connected(std::shared_ptr<Client> client) {
  ++clients_open_;
  std::lock_guard lock(mutex_);
  inbox_.push_back({Inbound::Kind::connect, std::move(client), {}, {}, {}});
  inbox_ready_.store(true, std::memory_order_release);
  cv_.notify_one();
}

void WorldHost::disconnected(std::shared_ptr<Client> client) {
  --clients_open_;
  std::lock_guard lock(mutex_);
  inbox_.push_back({Inbound::Kind::disconnect, std::move(client), {}, {}, {}});
  inbox_ready_.store(true, std::memory_order_release);
  cv_.notify_one();
}

void WorldHost::post(std::shared_ptr<Client> client, json message) {
  std::lock_guard lock(mutex_);
  inbox_.push_back({Inbound::Kind::message, std::move(client), std::move(message), {}, {}});
  inbox_ready_.store(true, std::memory_order_release);
  cv_.notify_one();
}

void WorldHost::request_state(std::function<void(std::string)> done) {
  std::lock_guard lock(mutex_);
  inbox_.push_back({Inbound::Kind::state, nullptr, {}, std::move(done), {}});
  inbox_ready_.store(true, std::memory_order_release);
  cv_.notify_one();
}

void WorldHost::request_stop(std::string reason) {
  std::lock_guard lock(mutex_);
  inbox_.push_back({Inbound::Kind::stop, nullptr, {}, {}, std::move(reason)});
  inbox_ready_.store(true, std::memory_order_release);
  cv_.notify_one();
}

// ---- the simulation thread ----------------------------------------------------------------------

double WorldHost::now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void WorldHost::reanchor() {
  anchor_wall_ = now();
  anchor_sim_ = server_ ? server_->time() : 0.0;
}

void WorldHost::drain_inbox() {
  std::deque<Inbound> batch;
  {
    std::lock_guard lock(mutex_);
    if (inbox_.empty()) return;  // most boundaries: no deque to build (it allocates) and free
    batch.swap(inbox_);
    inbox_ready_.store(false, std::memory_order_relaxed);
  }
  for (Inbound& in : batch) handle(in);
}

bool WorldHost::wait_inbox_until(double deadline) {
  // Spin a little before sleeping: a lockstep client's next command usually arrives within tens of
  // microseconds, and waking a sleeping thread on an idle vCPU costs as much again (measured: a
  // command that waits for a control step took ~80 us more on the quiet machine than under load;
  // docs/performance.md). At most kSpin of CPU per wait, so pacing and paused waits lose nothing.
  constexpr double kSpin = 100e-6;
  const double spin_end = std::min(deadline, now() + kSpin);
  while (now() < spin_end) {
    if (inbox_ready_.load(std::memory_order_acquire)) return true;
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
  std::unique_lock lock(mutex_);
  const double wait = std::max(0.0, deadline - now());
  return cv_.wait_for(lock, std::chrono::duration<double>(wait), [&] { return !inbox_.empty(); });
}

int WorldHost::run() {
  reanchor();
  if (options_.until && server_->time() >= *options_.until) {
    stopping_ = true;
    stop_reason_ = "until";
  }
  while (!stopping_) {
    drain_inbox();
    if (stopping_) break;
    do_file_requests();
    const double t_now = now();
    send_due_frames(t_now);
    double deadline = t_now + 0.5;
    for (const auto& [key, s] : streams_) deadline = std::min(deadline, s.next_due);
    if (ended_ || (paused_ && steps_left_ == 0)) {
      wait_inbox_until(deadline);
      continue;
    }
    double target = server_->world().dt() > 0.0 ? static_cast<double>(server_->step() + 1) * scene_.def.dt : 0.0;
    if (options_.replay && !replay_target(target)) {  // at an end of the recording: it pauses there
      paused_ = true;
      steps_left_ = 0;
      broadcast_status();
      continue;
    }
    if (options_.until && target > *options_.until) target = *options_.until;
    if (speed_ > 0.0 && steps_left_ == 0) {
      const double due = anchor_wall_ + std::abs(target - anchor_sim_) / speed_;
      if (t_now < due) {
        wait_inbox_until(std::min(deadline, due));
        continue;
      }
      if (t_now - due > 0.25) {  // behind: go on from now rather than catch up in a burst
        anchor_wall_ = t_now;
        anchor_sim_ = target;
      }
    }
    step_end_ = server_->step() + 1;
    if (options_.replay && target < server_->time()) seek(target);
    else step_world(target);
    bool changed = false;
    if (steps_left_ > 0 && --steps_left_ == 0) changed = true;
    if (pause_at_ && server_->time() >= *pause_at_) {
      paused_ = true;
      pause_at_.reset();
      changed = true;
    }
    if (changed && !ended_) broadcast_status();
    if (options_.until && server_->time() >= *options_.until) {
      stopping_ = true;
      stop_reason_ = "until";
    }
  }
  // Stopped at a control boundary: flush the logs, tell every client, close.
  fan_out_events();
  if (events_file_) events_file_->flush();
  if (inputs_file_) inputs_file_->flush();
  if (recorder_) finish_recording(stop_reason_ == "until" ? "" : stop_reason_);
  const std::string bye = dump({{"type", "bye"}, {"reason", stop_reason_}, {"t", server_->time()}});
  for (auto& [id, c] : clients_) {
    c.client->send(std::make_shared<const std::string>(bye));
    c.client->close_after_send();
  }
  spdlog::info("stopped at t={} ({})", fmt(server_->time()), stop_reason_);
  if (on_finished) on_finished();
  return 0;
}

void WorldHost::step_world(double target) {
  in_step_ = true;
  try {
    advance(target);
  } catch (const std::exception& e) {
    in_step_ = false;
    fan_out_events();
    end_world(e.what());
    return;
  }
  in_step_ = false;
  fan_out_events();
}

void WorldHost::fan_out_events() {
  if (events_.empty()) return;
  if (events_writer_) events_writer_->write(events_);
  if (recorder_) recorder_->events(events_);
  bool wanted = false;
  for (const auto& [key, s] : streams_) wanted = wanted || s.kind().all_events || !s.kind().events.empty();
  if (wanted) {
    std::string line;
    for (const turtle::LogEvent& e : events_) {
      line.clear();
      formats::append_event(line, formats::event_line(e));
      if (!line.empty() && line.back() == '\n') line.pop_back();
      for (auto& [key, s] : streams_) s.add_event(e.kind, line, options_.limits.max_frame_events);
    }
  }
  events_.clear();
}

void WorldHost::end_world(const std::string& reason) {
  ended_ = reason;
  if (recorder_) finish_recording("ended: " + reason, false);
  spdlog::error("the world ended at t={}: {}", fmt(server_->time()), reason);
  // Changes waiting for a boundary that will not come are answered now.
  auto refuse = [&](std::uint64_t client, const json& id, const char* request) {
    auto it = clients_.find(client);
    if (it == clients_.end()) return;
    ++it->second.errors;
    reply_text(it->second, error_text("ended", "the world has ended (" + reason + ") before the change was made", &id, request));
  };
  for (const WallChange& w : wall_changes_) refuse(w.client, w.id, "add_wall");
  for (const Takeover& t : takeovers_) refuse(t.client, t.id, "claim");
  wall_changes_.clear();
  takeovers_.clear();
  refuse_body_changes(reason);
  broadcast_status();
}

std::vector<bool> WorldHost::claimed() const {
  std::vector<bool> out(slots_.size());
  for (std::size_t i = 0; i < slots_.size(); ++i) out[i] = slots_[i].owner != 0;
  return out;
}

FrameClock WorldHost::clock() const {
  FrameClock c;
  c.wall = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  c.paused = paused_ && steps_left_ == 0;
  c.speed = speed_ > 0.0 ? json(speed_) : json("max");
  return c;
}

void WorldHost::send_due_frames(double t_now) {
  if (streams_.empty()) return;
  std::map<std::string, std::vector<Client*>> members;
  for (auto& [id, c] : clients_)
    if (c.stream) members[*c.stream].push_back(c.client.get());
  const std::vector<bool> claims = claimed();
  for (auto it = streams_.begin(); it != streams_.end();) {
    auto m = members.find(it->first);
    if (m == members.end()) {
      it = streams_.erase(it);
      continue;
    }
    FrameStream& s = it->second;
    if (s.next_due <= t_now) {
      const std::shared_ptr<const std::string> frame = s.build(*server_, claims, clock());
      ++frames_built_;
      for (Client* c : m->second) c->send_frame(frame, s.kind().binary);
      s.next_due += 1.0 / s.kind().rate;
      if (s.next_due < t_now) s.next_due = t_now + 1.0 / s.kind().rate;
    }
    ++it;
  }
}

// ---- messages -------------------------------------------------------------------------------------

void WorldHost::reply(ClientState& c, const json& message) { reply_text(c, dump(message)); }

void WorldHost::reply_text(ClientState& c, std::string text) {
  c.client->send(std::make_shared<const std::string>(std::move(text)));
}

void WorldHost::broadcast(const std::string& text) {
  const auto shared = std::make_shared<const std::string>(text);
  for (auto& [id, c] : clients_)
    if (c.hello) c.client->send(shared);
}

void WorldHost::broadcast_status() { broadcast(dump({{"type", "status"}, {"status", status_json()}})); }

json WorldHost::status_json() const {
  json st = {{"t", server_->time()},
          {"step", server_->step()},
          {"paused", paused_ && steps_left_ == 0},
          {"speed", speed_ > 0.0 ? json(speed_) : json("max")},
          {"until", pause_at_ ? json(*pause_at_) : json(nullptr)},
          {"ended", ended_ ? json(*ended_) : json(nullptr)}};
  if (options_.replay)
    st["replay"] = {{"end", options_.replay->end}, {"reverse", reverse_}, {"complete", options_.replay->complete}};
  return st;
}

json WorldHost::world_json() const {
  const sim::WorldDef& def = scene_.def;
  json turtles = json::array();
  for (std::size_t i = 0; i < server_->turtle_count(); ++i) {
    json sensors = json::array();
    for (const turtle::SensorArc& a : scene_.programs[i].sensors) sensors.push_back(a.name);
    turtles.push_back({{"id", def.turtles[i].id},
                       {"index", i},
                       {"controller", server_->controller(i)},
                       {"remote", server_->is_remote(i)},
                       {"claimed", slots_[i].owner != 0},
                       {"radius", server_->world().turtle_radius(i)},
                       {"sensors", sensors}});
  }
  return {{"name", def.name},
          {"arena", {{"width", def.arena.width}, {"height", def.arena.height}, {"boundary", std::string(sim::to_string(def.arena.boundary))}}},
          {"dt", def.dt},
          {"mode", sim::to_string(options_.mode)},
          {"remote", options_.realtime ? "realtime" : "lockstep"},
          {"balls", server_->world().ball_count()},
          {"walls", server_->world().walls().size()},
          {"turtles", turtles},
          {"views", views_json(*server_)}};
}

json WorldHost::ok(const json& m, const char* request) const {
  json r = {{"type", "ok"}};
  if (auto it = m.find("id"); it != m.end() && !it->is_null()) r["id"] = *it;
  r["request"] = request;
  r["status"] = status_json();
  return r;
}

std::size_t WorldHost::turtle_index(const json& m, const char* example) const {
  const std::string id = string_field(m, "turtle", example);
  for (std::size_t i = 0; i < scene_.def.turtles.size(); ++i)
    if (scene_.def.turtles[i].id == id) return i;
  std::string known;
  for (const sim::TurtleDef& t : scene_.def.turtles) known += (known.empty() ? "" : ", ") + t.id;
  throw RequestError("unknown_turtle", "/turtle: no turtle '" + id + "' in this world (turtles: " +
                                           (known.empty() ? "none" : known) + ")",
                     "/turtle");
}

void WorldHost::require_live() const {
  if (ended_)
    throw RequestError("ended", "the world has ended (" + *ended_ + "); `load` a world to go on");
}

void WorldHost::write_input(const std::string& line) {
  if (inputs_file_) *inputs_file_ << line;
  if (recorder_) recorder_->input(line);
}

void WorldHost::handle(Inbound& in) {
  switch (in.kind) {
    case Inbound::Kind::connect: {
      ClientState c;
      c.client = in.client;
      c.authorized = !options_.token;
      clients_.emplace(in.client->id, std::move(c));
      return;
    }
    case Inbound::Kind::disconnect: {
      auto it = clients_.find(in.client->id);
      if (it == clients_.end()) return;
      release_all(it->second, "disconnected");
      clients_.erase(it);
      return;
    }
    case Inbound::Kind::state: {
      in.state_done(state_text());
      return;
    }
    case Inbound::Kind::stop:
      stopping_ = true;
      stop_reason_ = in.reason;
      return;
    case Inbound::Kind::message: break;
  }
  auto it = clients_.find(in.client->id);
  if (it == clients_.end()) return;  // it went away meanwhile
  ClientState& c = it->second;
  ++c.messages;
  try {
    handle_message(c, in.message);
  } catch (const RequestError& e) {
    ++c.errors;
    reply_text(c, error_reply(in.message, e));
  }
}

void WorldHost::release_all(ClientState& c, const char* why) {
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    Slot& s = slots_[i];
    if (s.owner != c.client->id) continue;
    s.owner = 0;
    if (s.queued) {  // accepted, not yet taken: dropped
      s.queued.reset();
      s.busy = false;
    }
    if (s.busy) s.orphan = true;
    spdlog::info("turtle '{}' released ({}, connection {}); it stands still", scene_.def.turtles[i].id, why, c.client->id);
  }
  std::erase_if(takeovers_, [&](const Takeover& t) { return t.client == c.client->id; });
  c.claims = 0;
}

void WorldHost::handle_message(ClientState& c, const json& m) {
  if (!m.is_object()) throw RequestError("not_object", "a message is a JSON object with a \"type\", e.g. {\"type\": \"hello\", \"protocol\": \"turtlegas/1\"}");
  check_id(m);
  const auto type_it = m.find("type");
  if (type_it == m.end())
    throw RequestError("missing_field", "/type is missing: every message has a \"type\", e.g. {\"type\": \"ping\"}", "/type");
  if (!type_it->is_string())
    throw RequestError("wrong_type", "/type must be a string, e.g. {\"type\": \"ping\"}", "/type");
  const std::string& type = type_it->get_ref<const std::string&>();
  const std::vector<std::string>& types = message_types();
  if (std::find(types.begin(), types.end(), type) == types.end()) {
    std::string known;
    for (const std::string& t : types) known += (known.empty() ? "" : ", ") + t;
    throw RequestError("unknown_type", "/type: no message \"" + type.substr(0, 64) + "\" in turtlegas/1 (known: " + known + ")", "/type");
  }
  const json id = m.contains("id") ? m.at("id") : json(nullptr);

  if (type == "hello") {
    constexpr std::string_view ex = R"({"type": "hello", "protocol": "turtlegas/1"})";
    const std::string protocol = string_field(m, "protocol", ex);
    if (protocol != protocol_name)
      throw RequestError("bad_protocol", "/protocol: this server speaks \"turtlegas/1\" (got \"" + protocol.substr(0, 64) + "\")", "/protocol");
    if (options_.token && m.contains("token")) {
      const std::string token = string_field(m, "token", R"({"type": "hello", "protocol": "turtlegas/1", "token": "T"})");
      if (token != *options_.token) {
        c.hello = true;
        throw RequestError("bad_token", "/token is not the server's token; the connection stays unauthorized (view only, from loopback)", "/token");
      }
      c.authorized = true;
    }
    c.hello = true;
    const Limits& l = options_.limits;
    json welcome = {{"type", "welcome"}};
    if (!id.is_null()) welcome["id"] = id;
    welcome["protocol"] = protocol_name;
    welcome["server"] = server_name;
    welcome["connection"] = c.client->id;
    welcome["authorized"] = c.authorized;
    welcome["world"] = world_json();
    welcome["status"] = status_json();
    welcome["capabilities"] = options_.replay ? json{"frames", "binary-frames", "control", "views", "replay"}
                                              : json{"frames", "binary-frames", "control", "remote", "add_wall", "spawn",
                                                     "remove", "teleport", "save", "load", "views"};
    welcome["limits"] = {{"max_message", l.max_message}, {"max_rate", l.max_rate}, {"max_claims", l.max_claims}, {"max_clients", l.max_clients}};
    reply(c, welcome);
    return;
  }
  if (!c.hello)
    throw RequestError("hello_first", "say hello first: {\"type\": \"hello\", \"protocol\": \"turtlegas/1\"}");
  if (type == "ping") {
    json r = {{"type", "pong"}};
    if (!id.is_null()) r["id"] = id;
    r["t"] = server_->time();
    r["wall"] = clock().wall;
    reply(c, r);
    return;
  }
  if (type == "stats") {
    json r = {{"type", "stats"}};
    if (!id.is_null()) r["id"] = id;
    r["connection"] = c.client->id;
    r["messages"] = c.messages;
    r["errors"] = c.errors + c.client->local_errors.load();
    r["frames_sent"] = c.client->frames_sent.load();
    r["frames_dropped"] = c.client->frames_dropped.load();
    r["bytes_sent"] = c.client->bytes_sent.load();
    r["frames_built"] = frames_built_;
    r["clients"] = clients_.size();
    reply(c, r);
    return;
  }
  const bool view = type == "subscribe" || type == "unsubscribe" || type == "snapshot";
  if (view ? !(c.authorized || c.client->loopback) : !c.authorized)
    throw RequestError("unauthorized", view ? "frames to a non-loopback peer need the token: send it in the hello"
                                            : "\"" + type + "\" needs the server's token: say hello with \"token\"");

  if (type == "subscribe") {
    constexpr std::string_view ex = R"({"type": "subscribe", "rate": 30, "events": ["touch"], "format": "json"})";
    FrameKind k;
    if (auto r = optional_number(m, "rate", ex)) {
      if (!(*r > 0.0 && *r <= 120.0)) throw RequestError("bad_value", "/rate must be > 0 and <= 120 frames per second", "/rate");
      k.rate = *r;
    }
    if (m.contains("format")) {
      const std::string f = string_field(m, "format", ex);
      if (f != "json" && f != "binary") throw RequestError("bad_value", "/format must be \"json\" or \"binary\"", "/format");
      k.binary = f == "binary";
      if (k.binary && !c.client->binary_capable())
        throw RequestError("unsupported", "/format: binary frames need a WebSocket; TCP lines carry \"json\" frames", "/format");
    }
    if (auto v = optional_bool(m, "velocities", ex)) k.velocities = *v;
    if (auto r = m.find("region"); r != m.end()) {
      constexpr const char* why = "/region must be [x0, y0, x1, y1], four finite numbers with x0 < x1 and y0 < y1";
      if (!r->is_array() || r->size() != 4 || !std::all_of(r->begin(), r->end(), [](const json& x) { return x.is_number(); }))
        throw RequestError("wrong_type", why, "/region");
      std::array<double, 4> box{};
      for (std::size_t q = 0; q < 4; ++q) box[q] = (*r)[q].get<double>();
      if (!std::all_of(box.begin(), box.end(), [](double x) { return std::isfinite(x); }) || !(box[0] < box[2]) || !(box[1] < box[3]))
        throw RequestError("bad_value", why, "/region");
      k.region = box;
    }
    if (auto e = m.find("events"); e != m.end()) {
      if (e->is_string() && e->get<std::string>() == "all") {
        k.all_events = true;
      } else if (e->is_array()) {
        for (const json& x : *e) {
          if (!x.is_string()) throw RequestError("wrong_type", "/events must be \"all\" or an array of event kinds (strings), e.g. [\"touch\"]", "/events");
          k.events.push_back(x.get<std::string>());
        }
        std::sort(k.events.begin(), k.events.end());
        k.events.erase(std::unique(k.events.begin(), k.events.end()), k.events.end());
      } else {
        throw RequestError("wrong_type", "/events must be \"all\" or an array of event kinds (strings), e.g. [\"touch\"]", "/events");
      }
    }
    const std::string key = k.key();
    auto [sit, fresh] = streams_.try_emplace(key, k, *server_);
    if (fresh) sit->second.next_due = now();
    c.stream = key;
    json r = {{"type", "subscribed"}};
    if (!id.is_null()) r["id"] = id;
    r["rate"] = k.rate;
    r["events"] = k.all_events ? json("all") : json(k.events);
    r["format"] = k.binary ? "binary" : "json";
    r["velocities"] = k.velocities;
    if (k.region) r["region"] = *k.region;
    reply(c, r);
    reply_text(c, snapshot_text(*server_, ball_ids_, claimed(), clock(), nullptr, world_json()["arena"], looks_));
    return;
  }
  if (type == "unsubscribe") {
    c.stream.reset();
    reply(c, ok(m, "unsubscribe"));
    return;
  }
  if (type == "snapshot") {
    reply_text(c, snapshot_text(*server_, ball_ids_, claimed(), clock(), id, world_json()["arena"], looks_));
    return;
  }
  if (is_view_message(type)) return handle_view_message(c, m, type);
  if (type == "spawn" || type == "remove" || type == "teleport") {
    queue_body_change(c, m, type);
    return;  // answered at the next boundary
  }

  if (type == "play" || type == "seek" || type == "reverse") {
    if (!options_.replay)
      throw RequestError("not_replay", "\"" + type + "\" is for recordings: it works in `turtlegas replay R.tgrec`, not in a live world");
    const double end = options_.replay->end;
    pause_at_.reset();
    steps_left_ = 0;
    if (type == "seek") {
      const double t = number_field(m, "t", R"({"type": "seek", "t": 2.5})");
      if (!(t >= 0.0 && t <= end))
        throw RequestError("bad_value", "/t must be from 0 to the recording's end, " + fmt(end) + " s", "/t");
      seek(t);
      paused_ = true;
    } else {
      reverse_ = type == "reverse";
      paused_ = false;
      reanchor();
    }
    reply(c, ok(m, type.c_str()));
    broadcast_status();
    return;
  }
  if (options_.replay && type != "pause" && type != "resume" && type != "step" && type != "speed" && type != "run_until")
    require_not_replay(type);

  if (type == "pause" || type == "resume" || type == "step" || type == "speed" || type == "run_until") {
    require_live();
    if (type == "pause" || type == "resume") pause_at_.reset();  // both cancel a run_until's stop
    if (type == "pause") {
      paused_ = true;
      steps_left_ = 0;
    } else if (type == "resume") {
      paused_ = false;
      reverse_ = false;  // a replay: forward, as play
      steps_left_ = 0;
      reanchor();
    } else if (type == "step") {
      pause_at_.reset();
      double n = 1;
      if (auto v = optional_number(m, "steps", R"({"type": "step", "steps": 1})")) n = *v;
      if (!(n >= 1 && n <= 1e6 && n == std::floor(n)))
        throw RequestError("bad_value", "/steps must be a whole number from 1 to 1000000", "/steps");
      // Counted from the boundary it is handled at. Handled inside a step, at the boundary that
      // step ends on (a lockstep wait there, a remote turtle asked for its command), that step's
      // own end counts one off: add it, or a `step` sent while the previous one runs is
      // swallowed by it, and a change waiting for the boundary it asks for never comes.
      steps_left_ = static_cast<std::uint64_t>(n) + (in_step_ && server_->step() == step_end_ ? 1 : 0);
      paused_ = true;
    } else if (type == "speed") {
      const auto f = m.find("factor");
      if (f == m.end()) throw RequestError("missing_field", "/factor is missing: a number from 0.01 to 1000, or \"max\"; send e.g. {\"type\": \"speed\", \"factor\": 2}", "/factor");
      if (f->is_string() && f->get<std::string>() == "max") {
        speed_ = 0.0;
      } else if (f->is_number()) {
        const double v = f->get<double>();
        if (!(v >= 0.01 && v <= 1000.0)) throw RequestError("bad_value", "/factor must be from 0.01 to 1000, or \"max\"", "/factor");
        speed_ = v;
      } else {
        throw RequestError("wrong_type", "/factor must be a number from 0.01 to 1000, or \"max\"", "/factor");
      }
      reanchor();
    } else {
      const double t = number_field(m, "t", R"({"type": "run_until", "t": 10})");
      if (!(t > server_->time()))
        throw RequestError("bad_value", "/t must be later than the world's time (" + fmt(server_->time()) + " s)", "/t");
      if (options_.replay && t > options_.replay->end)
        throw RequestError("bad_value", "/t must be at most the recording's end, " + fmt(options_.replay->end) + " s", "/t");
      reverse_ = false;
      pause_at_ = t;
      paused_ = false;
      steps_left_ = 0;
      reanchor();
    }
    reply(c, ok(m, type.c_str()));
    return;
  }
  if (type == "claim") {
    require_live();
    constexpr std::string_view ex = R"({"type": "claim", "turtle": "t1"})";
    const std::size_t i = turtle_index(m, ex.data());
    const bool takeover = optional_bool(m, "takeover", ex).value_or(false);
    Slot& s = slots_[i];
    const std::string& tid = scene_.def.turtles[i].id;
    if (server_->turtle_status(i).gone)
      throw RequestError("unknown_turtle", "/turtle: '" + tid + "' is no longer in the world (removed, crushed or out of an open arena); claim a turtle that is", "/turtle");
    if (s.owner == c.client->id) throw RequestError("claimed", "/turtle: this connection has claimed '" + tid + "' already", "/turtle");
    if (s.owner != 0 || std::any_of(takeovers_.begin(), takeovers_.end(), [&](const Takeover& t) { return t.turtle == i; }))
      throw RequestError("claimed", "/turtle: '" + tid + "' is claimed by another connection; it is free again when that one releases it or closes", "/turtle");
    if (c.claims >= options_.limits.max_claims)
      throw RequestError("too_many_claims", "a connection may claim at most " + std::to_string(options_.limits.max_claims) + " turtles; release one first");
    if (server_->is_remote(i)) {
      s.owner = c.client->id;
      ++c.claims;
      json r = {{"type", "claimed"}};
      if (!id.is_null()) r["id"] = id;
      json sensors = json::array();
      for (const turtle::SensorArc& a : scene_.programs[i].sensors) sensors.push_back(a.name);
      r.update({{"turtle", tid}, {"index", i}, {"sensors", sensors}, {"takeover", false}, {"t", server_->time()}, {"step", server_->step()}});
      reply(c, r);
      return;
    }
    if (!takeover)
      throw RequestError("not_remote", "/turtle: '" + tid + "' runs the program '" + server_->controller(i) +
                                           "'; claim it with \"takeover\": true to detach that program, or make its controller \"remote\" in the world file",
                         "/turtle");
    ++c.claims;
    takeovers_.push_back({c.client->id, id, i});
    return;  // answered at the next boundary
  }
  if (type == "release") {
    const std::size_t i = turtle_index(m, R"({"type": "release", "turtle": "t1"})");
    Slot& s = slots_[i];
    if (s.owner != c.client->id)
      throw RequestError("not_claimed", "/turtle: this connection has not claimed '" + scene_.def.turtles[i].id + "'", "/turtle");
    s.owner = 0;
    if (s.queued) {
      s.queued.reset();
      s.busy = false;
    }
    if (s.busy) s.orphan = true;
    if (c.claims > 0) --c.claims;
    reply(c, ok(m, "release"));
    return;
  }
  if (is_command(type)) {
    require_live();
    const std::string ex = "{\"type\": \"" + type + "\", \"turtle\": \"t1\"" + (type == "pen" ? ", \"down\": true}" : type == "yield" ? "}" : ", \"amount\": 100}");
    const std::size_t i = turtle_index(m, ex.c_str());
    const turtle::RemoteCommand cmd = read_command(m, type);  // the message first, then the turtle's state
    Slot& s = slots_[i];
    const std::string& tid = scene_.def.turtles[i].id;
    if (server_->turtle_status(i).gone)
      throw RequestError("unknown_turtle", "/turtle: '" + tid + "' is no longer in the world (removed, crushed or out of an open arena)", "/turtle");
    if (s.owner != c.client->id)
      throw RequestError("not_claimed", "/turtle: claim '" + tid + "' first: {\"type\": \"claim\", \"turtle\": \"" + tid + "\"}", "/turtle");
    if (s.busy)
      throw RequestError("busy", "/turtle: '" + tid + "' has not finished its previous command; wait for its result", "/turtle");
    if (server_->turtle_status(i).finished)
      throw RequestError("refused", "/turtle: '" + tid + "' is parked for good (its program stopped: " + server_->turtle_status(i).fault + ")", "/turtle");
    s.queued = cmd;
    s.queued_id = id;
    s.busy = true;
    return;  // answered by its result
  }
  if (type == "add_wall") {
    require_live();
    constexpr std::string_view ex = R"({"type": "add_wall", "wall": {"id": "w-new", "from": [100, 300], "to": [200, 300]}})";
    const auto w = m.find("wall");
    if (w == m.end()) throw RequestError("missing_field", "/wall is missing; send e.g. " + std::string(ex), "/wall");
    if (!w->is_object()) throw RequestError("wrong_type", "/wall must be an object; send e.g. " + std::string(ex), "/wall");
    WallChange change{c.client->id, id, {}};
    const auto wid = w->find("id");
    if (wid == w->end()) throw RequestError("missing_field", "/wall/id is missing: a wall needs an id no body has; send e.g. " + std::string(ex), "/wall/id");
    if (!wid->is_string() || wid->get_ref<const std::string&>().empty() || wid->get_ref<const std::string&>().size() > 200)
      throw RequestError("wrong_type", "/wall/id must be a non-empty string of at most 200 characters", "/wall/id");
    change.wall.id = wid->get<std::string>();
    change.wall.from = point_field(*w, "from", "/wall", ex);
    change.wall.to = point_field(*w, "to", "/wall", ex);
    wall_changes_.push_back(std::move(change));
    return;  // answered at the next boundary
  }
  if (type == "save" || type == "load") {
    if (type == "save") require_live();
    if (options_.save_dir.empty())
      throw RequestError("no_save_dir", "save and load need a directory: start the server with --save-dir DIR");
    const std::string file = string_field(m, "file", type == "save" ? R"({"type": "save", "file": "snap.json"})" : R"({"type": "load", "file": "room.json"})");
    check_plain_name(file);
    file_requests_.push_back({c.client->id, id, type == "load", file});
    return;
  }
}

void WorldHost::at_boundary(turtle::WorldServer& server, std::uint64_t step) {
  // A replay has no remote turtles and takes no changes; and its messages must wait for the main
  // loop: a seek handled here, inside run_until, would rebuild the world under it, and a state
  // request would see a seek's way rather than its end.
  if (options_.replay) return;
  drain_inbox();
  while (!takeovers_.empty()) {
    const Takeover t = takeovers_.front();
    takeovers_.pop_front();
    auto it = clients_.find(t.client);
    if (it == clients_.end()) continue;
    server.make_remote(t.turtle);
    write_input(formats::input_takeover_line(step, scene_.def.turtles[t.turtle].id));
    Slot& s = slots_[t.turtle];
    s = Slot{};
    s.owner = t.client;
    json r = {{"type", "claimed"}};
    if (!t.id.is_null()) r["id"] = t.id;
    json sensors = json::array();
    for (const turtle::SensorArc& a : scene_.programs[t.turtle].sensors) sensors.push_back(a.name);
    r.update({{"turtle", scene_.def.turtles[t.turtle].id}, {"index", t.turtle}, {"sensors", sensors}, {"takeover", true},
              {"t", server.time()}, {"step", step}});
    reply(it->second, r);
  }
  while (!wall_changes_.empty()) {
    WallChange w = std::move(wall_changes_.front());
    wall_changes_.pop_front();
    auto it = clients_.find(w.client);
    try {
      server.add_wall(w.wall);
      write_input(formats::input_wall_line(step, w.wall));
      if (it != clients_.end()) {
        json m = {{"id", w.id}};
        reply(it->second, ok(m, "add_wall"));
      }
    } catch (const std::invalid_argument& e) {
      if (it != clients_.end()) {
        ++it->second.errors;
        reply_text(it->second, error_text("refused", std::string("/wall: ") + e.what(), &w.id, "add_wall", "/wall"));
      }
    }
  }
  apply_body_changes(server, step);
}

std::optional<turtle::RemoteCommand> WorldHost::next_command(std::uint64_t step, std::size_t turtle) {
  drain_inbox();
  Slot& s = slots_[turtle];
  if (!s.queued && s.owner != 0 && !options_.realtime && !stopping_) {
    const double deadline = now() + options_.lockstep_timeout;
    while (!s.queued && s.owner != 0 && !stopping_) {
      const double t = now();
      if (t >= deadline)
        throw LockstepTimeout("lockstep timeout: turtle '" + scene_.def.turtles[turtle].id + "' (claimed by connection " +
                              std::to_string(s.owner) + ") sent no command for " + fmt(options_.lockstep_timeout) +
                              " s at t=" + fmt(server_->time()) +
                              "; answer every result with a command, or serve with --realtime or a longer --lockstep-timeout");
      send_due_frames(t);
      double wake = deadline;
      for (const auto& [key, st] : streams_) wake = std::min(wake, st.next_due);
      wait_inbox_until(wake);
      drain_inbox();
    }
  }
  if (!s.queued) return std::nullopt;
  const turtle::RemoteCommand c = *s.queued;
  s.queued.reset();
  s.inflight_id = s.queued_id;
  s.queued_id = nullptr;
  write_input(formats::input_command_line(step, scene_.def.turtles[turtle].id, c));
  return c;
}

void WorldHost::on_report(const turtle::RemoteReport& r) {
  Slot& s = slots_[r.turtle];
  json id = nullptr;
  bool deliver = s.owner != 0;
  if (r.kind == turtle::RemoteReport::Kind::result) {
    id = s.inflight_id;
    s.inflight_id = nullptr;
    s.busy = false;
    deliver = deliver && !s.orphan;
    s.orphan = false;
  } else if (r.kind == turtle::RemoteReport::Kind::fault) {
    s.busy = false;
    s.orphan = false;
  }
  if (!deliver) return;
  auto it = clients_.find(s.owner);
  if (it == clients_.end()) return;
  reply_text(it->second, report_text(r, scene_.def.turtles[r.turtle].id, id));
}

void WorldHost::do_file_requests() {
  while (!file_requests_.empty()) {
    const FileRequest f = file_requests_.front();
    file_requests_.pop_front();
    auto it = clients_.find(f.client);
    auto fail = [&](const char* code, const std::string& message) {
      if (it == clients_.end()) return;
      ++it->second.errors;
      reply_text(it->second, error_text(code, message, &f.id, f.load ? "load" : "save", "/file"));
    };
    const std::filesystem::path path = options_.save_dir / f.file;
    std::error_code ec;
    const auto st = std::filesystem::symlink_status(path, ec);
    if (!ec && std::filesystem::is_symlink(st)) {
      fail("bad_path", "/file: '" + f.file + "' is a symlink; save and load touch only plain files in the save directory");
      continue;
    }
    if (!f.load) {
      if (ended_) {
        fail("ended", "the world has ended (" + *ended_ + ")");
        continue;
      }
      const std::filesystem::path tmp = options_.save_dir / ("." + f.file + ".tmp-" + std::to_string(::getpid()));
      {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (out) formats::write_state(out, server_->world(), formats::RunNames{ball_ids_, scene_.def, server_->world()});
        if (!out) {
          std::filesystem::remove(tmp, ec);
          fail("bad_path", "/file: cannot write '" + f.file + "' in the save directory");
          continue;
        }
      }
      std::filesystem::rename(tmp, path, ec);
      if (ec) {
        std::filesystem::remove(tmp, ec);
        fail("bad_path", "/file: cannot write '" + f.file + "' in the save directory");
        continue;
      }
      if (it != clients_.end()) {
        json m = {{"id", f.id}};
        json r = ok(m, "save");
        r["file"] = f.file;
        reply(it->second, r);
      }
      continue;
    }
    if (!std::filesystem::is_regular_file(path, ec)) {
      fail("not_found", "/file: no file '" + f.file + "' in the save directory");
      continue;
    }
    world::Scene scene;
    std::string text;
    try {
      std::ifstream in(path, std::ios::binary);
      std::ostringstream buf;
      buf << in.rdbuf();
      text = buf.str();
      scene = world::parse_scene(text, f.file, registry_);
      // Built before anything is let go: a world the runtime refuses changes nothing.
      turtle::ServerOptions probe;
      probe.mode = options_.mode;
      (void)world::make_server(scene, registry_, probe);
    } catch (const std::exception& e) {
      fail("bad_world", e.what());
      continue;
    }
    for (auto& [cid, c] : clients_) release_all(c, "load");
    fan_out_events();
    if (events_file_) events_file_->flush();
    if (inputs_file_) inputs_file_->flush();
    events_writer_.reset();
    events_file_.reset();
    inputs_file_.reset();
    if (recorder_) finish_recording("load");
    build_world(std::move(scene));
    {
      std::lock_guard lock(text_mutex_);
      options_.world_text = std::move(text);
    }
    std::map<std::string, FrameStream> fresh;
    for (auto& [key, s] : streams_) fresh.try_emplace(key, s.kind(), *server_).first->second.next_due = now();
    streams_ = std::move(fresh);
    spdlog::info("loaded '{}'", f.file);
    if (it != clients_.end()) reply(it->second, ok(json{{"id", f.id}}, "load"));
    broadcast(dump({{"type", "world"}, {"world", world_json()}}));
    for (auto& [cid, c] : clients_)
      if (c.stream) reply_text(c, snapshot_text(*server_, ball_ids_, claimed(), clock(), nullptr, world_json()["arena"], looks_));
  }
}

void WorldHost::require_not_replay(const std::string& type) const {
  if (options_.replay)
    throw RequestError("replay", "\"" + type + "\" would change the world, and this is a replay of " + options_.replay->path +
                                     ": it can only play, pause, seek, reverse, step and change speed");
}

bool WorldHost::replay_target(double& target) {
  const double t = server_->time(), dt = scene_.def.dt, end = options_.replay->end;
  if (!reverse_ || steps_left_ > 0) {
    if (t >= end) return false;
    if (!(target > t)) target = std::nextafter(t, INFINITY);
    target = std::min(target, end);
    return true;
  }
  if (t <= 0.0) return false;
  target = dt > 0.0 ? std::max(0.0, (std::ceil(t / dt) - 1.0) * dt) : 0.0;
  if (!(target < t)) target = std::max(0.0, target - dt);
  return true;
}

void WorldHost::seek(double t) {
  const bool back = t < server_->time();
  fan_out_events();
  const bool restored = restore_snapshot(t);
  const bool rebuild = back && !restored;
  if (rebuild) {
    world::Scene scene = world::parse_scene(world_text(), options_.world_file, registry_);
    scene.def.dt = options_.replay->dt;
    build_world(std::move(scene));
  }
  in_step_ = true;
  try {
    replay_run_until(t);
  } catch (const std::exception& e) {
    in_step_ = false;
    events_.clear();
    end_world(e.what());
    return;
  }
  in_step_ = false;
  if (rebuild || restored) reopen_client_views();
  events_.clear();  // what happened on the way is not shown: the viewer jumps
  reanchor();
  if (!rebuild && !restored) return;
  std::map<std::string, FrameStream> fresh;
  for (auto& [key, s] : streams_) fresh.try_emplace(key, s.kind(), *server_).first->second.next_due = now();
  streams_ = std::move(fresh);
  for (auto& [cid, c] : clients_)
    if (c.stream) reply_text(c, snapshot_text(*server_, ball_ids_, claimed(), clock(), nullptr, world_json()["arena"], looks_));
}

}  // namespace turtlegas::server
