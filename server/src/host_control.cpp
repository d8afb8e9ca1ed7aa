// SPDX-License-Identifier: MIT
// The world host's clock controls (docs/protocol.md, "Control"): pause, resume, step, speed and
// run_until; and a replay's play, seek and reverse (docs/recording.md, "Replay").
#include <cmath>
#include <string>

#include "host_text.hpp"
#include "turtlegas/server/protocol.hpp"
#include "turtlegas/server/world_host.hpp"

namespace turtlegas::server {

using nlohmann::json;

void WorldHost::on_pacing(ClientState& c, const json& m, const std::string& type) {
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
}

void WorldHost::on_replay_control(ClientState& c, const json& m, const std::string& type) {
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
}

}  // namespace turtlegas::server
