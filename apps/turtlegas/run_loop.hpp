// SPDX-License-Identifier: MIT
// How the commands that run a world for long (run, tag, render) run it: in chunks, with a progress
// line on a terminal, --max-wall-seconds and --max-events, and SIGINT/SIGTERM (signals.hpp) seen
// both at the chunks' ends and inside one engine step (sim::World::set_stop_poll), so that each
// ends cleanly at a consistent point with what it made so far written.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>

#include <CLI/CLI.hpp>

#include "cli_common.hpp"
#include "scene_scales.hpp"
#include "signals.hpp"
#include "turtlegas/formats/stats_file.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::apps {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A line on stderr rewritten in place, only on a terminal and only once the work has taken 2 s,
/// at most five times a second: every command's progress line (Progress; test's and sweep's list
/// of what runs). clear() it before writing anything else on the terminal.
class StatusLine {
 public:
  /// `enabled` false: never shown (sweep --quiet).
  explicit StatusLine(bool enabled = true);
  StatusLine(const StatusLine&) = delete;
  StatusLine& operator=(const StatusLine&) = delete;
  ~StatusLine() { clear(); }

  /// Whether a line is due now; show() it if so.
  bool due() const;
  void show(const std::string& text);
  void clear();
  bool shown() const { return shown_; }

 private:
  Clock::time_point start_, last_{};
  bool enabled_;
  bool shown_ = false;
};

/// A run's progress line (a StatusLine): what is being done ("round 3 of 20: "), the simulated
/// time of this part of the work, events per second, and when all of it will be done.
class Progress {
 public:
  /// Work of `until` simulated seconds, shown as t / until.
  explicit Progress(double until);

  /// Work made of parts (a tournament's rounds, a render's frames): t / until is shown for the
  /// part, and the percentage and the ETA count `offset + t` of `total` simulated seconds.
  void set_part(double until, double offset, double total);
  void update(double t, std::uint64_t events, const std::string& doing);
  void clear() { line_.clear(); }

 private:
  double until_, offset_ = 0.0, total_;
  Clock::time_point since_{};
  double done0_ = 0.0;
  std::uint64_t events0_ = 0;
  StatusLine line_;
};

/// "ETA 3 min", from `done` of `total` simulated seconds made in `seconds` of wall clock: "ETA
/// unknown" before any is done.
std::string eta_text(double done, double total, double seconds);

/// The figures of a run's end, one definition for `run` and `sweep`: the balls still in, the energy
/// at the end, the deepest overlap (now, the deepest met at a contact, and `sampled`, the deepest of
/// the run's own samples), and, for a run by the world server, the turtles whose programs finished.
void finish_run(formats::RunFigures& run, const sim::World& world, const turtle::WorldServer* server = nullptr,
                const sim::Overlap& sampled = {});

/// Why the chunk loop ended.
enum class Stop { until, signal, max_wall_seconds, max_events };
using Stopped = std::pair<Stop, int>;  ///< and the signal, for Stop::signal

/// "", "SIGINT", "SIGTERM", "max-wall-seconds" or "max-events": a stats file's "stopped".
const char* stop_name(Stopped s);
/// exit_ok, exit_limit or 128 + the signal.
int exit_code_for(Stopped s);

/// Exit code of a command that stopped at --max-wall-seconds or --max-events before it was done
/// (its outputs are whole, up to where it got). Ctrl-C and SIGTERM give 130 and 143.
constexpr int exit_limit = 3;

/// --max-wall-seconds and --max-events, one definition with one range for every command that
/// takes them; `what` is "the run", "the tournament", ...; `written` what is written on a stop,
/// `ends` how the command ends then.
struct LimitOptions {
  double max_wall_seconds = 0.0;
  std::uint64_t max_events = 0;
  CLI::Option *wall_option = nullptr, *events_option = nullptr;
  void add_to(CLI::App& cmd, const std::string& what, const std::string& written, const std::string& ends = "exit 3");
  std::optional<double> wall_seconds() const;
  std::optional<std::uint64_t> events() const;
};

/// How the loop cuts a run into chunks. The physics does not depend on where a run is cut; the
/// cuts are where outputs are flushed, progress is shown, limits and Ctrl-C are looked at, and
/// checkpoints are written. A chunk starts small enough for the scene's predicted event rate
/// (scene_scales.hpp: a runaway scene still comes back every ~2^14 events) and then adapts to
/// about 0.1 s of wall time, halving above 0.25 s or 2^20 events, doubling below 0.05 s and 2^18.
struct Pace {
  double chunk = 0.0;
};

/// The first chunk: `natural` (a control step, a fraction of one) or, when the scene's scales
/// predict more, about 2^14 events' worth. Sets the scales' cell from the world.
Pace first_pace(SceneScales scales, const sim::World& world, double natural);

struct Limits {
  double until = 0.0;
  std::optional<double> max_wall_seconds;
  std::optional<std::uint64_t> max_events;
  std::optional<double> checkpoint_every;
  std::optional<double> keyframe_every;  ///< a recording's keyframes: cuts at its multiples
  std::optional<double> sample_every;    ///< the overlap's samples: cuts at its multiples
};

/// Makes `target` (a sim::World or a turtle::WorldServer) stop inside a step too: at a signal or
/// at --max-wall-seconds (a poll every 4096 events), and at --max-events (its event limit, counted
/// from `events_before`, the events of earlier worlds of the same command, plus its own).
template <class Target>
void stop_inside_steps(Target& target, const Limits& limits, Clock::time_point start, std::uint64_t events_before = 0) {
  target.set_stop_poll([start, wall = limits.max_wall_seconds] {
    return stop_signal() != 0 || (wall && seconds_since(start) >= *wall);
  });
  if (limits.max_events) target.set_event_limit(*limits.max_events - std::min(*limits.max_events, events_before));
}

/// Runs chunks from `from` (the engine having taken `events` events) until `limits.until` or a
/// stop. `advance(t)` runs to t and returns the engine's event count; `flush()` writes what the
/// chunk logged; `checkpoint(t, why)` is called at every multiple of checkpoint_every;
/// `cut(t, events, at_key, at_sample)` after every chunk (a recording's keyframes; the chunks are
/// also cut at every multiple of keyframe_every, and at_key says this is one; likewise at every
/// multiple of sample_every, and at_sample). An advance stopped inside a step (stop_inside_steps)
/// is flushed and ends the loop, the engine at its last event.
template <class Advance, class Flush, class AtCheckpoint, class AtCut>
Stopped run_in_chunks(double from, std::uint64_t events, const Limits& limits, Pace& pace, Clock::time_point start,
                      Progress& progress, const std::string& doing, Advance&& advance, Flush&& flush,
                      AtCheckpoint&& checkpoint, AtCut&& cut) {
  double t = from;
  double events_per_second = 0.0;  // simulated, measured over the last chunk
  auto next_multiple = [](double at, double every) { return every > 0.0 ? (std::floor(at / every) + 1.0) * every : INFINITY; };
  const double every = limits.checkpoint_every.value_or(0.0);
  double next_checkpoint = next_multiple(t, every);
  const double key_every = limits.keyframe_every.value_or(0.0);
  double next_key = next_multiple(t, key_every);
  const double sample_every = limits.sample_every.value_or(0.0);
  // The samples are at k x sample_every, k counted: finding k again from t (floor(t / every) + 1)
  // rounds to the instant just measured for some k, which then was measured twice, an ulp apart.
  double sample_k = sample_every > 0.0 ? std::floor(t / sample_every) + 1.0 : 0.0;
  auto next_sample_after = [&](double at) {
    if (!(sample_every > 0.0)) return static_cast<double>(INFINITY);
    while (!(sample_k * sample_every > at)) sample_k += 1.0;
    return sample_k * sample_every;
  };
  double next_sample = next_sample_after(t);
  while (t < limits.until) {
    if (const int sig = stop_signal()) return {Stop::signal, sig};
    if (limits.max_wall_seconds && seconds_since(start) >= *limits.max_wall_seconds) return {Stop::max_wall_seconds, 0};
    if (limits.max_events && events >= *limits.max_events) return {Stop::max_events, 0};
    double chunk = pace.chunk;
    // Near --max-events, a chunk of about what is left.
    if (limits.max_events && events_per_second > 0.0)
      chunk = std::min(chunk, std::max(static_cast<double>(*limits.max_events - events) / events_per_second, chunk / 1024));
    double next = std::min({limits.until, t + chunk, next_checkpoint, next_key, next_sample});
    if (!(next > t)) next = std::nextafter(t, INFINITY);  // a chunk below one ulp of t
    const auto chunk_start = Clock::now();
    const std::uint64_t before = events;
    try {
      events = advance(next);
    } catch (const sim::StopRequested&) {
      flush();
      if (const int sig = stop_signal()) return {Stop::signal, sig};
      return {Stop::max_wall_seconds, 0};
    } catch (const sim::EventLimitReached&) {
      flush();
      return {Stop::max_events, 0};
    }
    const double took = seconds_since(chunk_start);
    flush();
    const double done = static_cast<double>(events - before);
    events_per_second = done / (next - t);
    if ((took > 0.25 || done > 0x1p20) && pace.chunk / 2.0 > 0.0) pace.chunk /= 2.0;
    else if (took < 0.05 && done < 0x1p18 && pace.chunk * 2.0 < INFINITY) pace.chunk *= 2.0;
    t = next;
    const bool at_key = t >= next_key;
    if (at_key) next_key = next_multiple(t, key_every);
    const bool at_sample = t >= next_sample;
    if (at_sample) next_sample = next_sample_after(t);
    cut(t, events, at_key, at_sample);
    note_run_time(t);
    if (t >= next_checkpoint) {
      checkpoint(t, "every " + fmt(every) + " s");
      next_checkpoint = next_multiple(t, every);
    }
    progress.update(t, events, doing);
  }
  return {Stop::until, 0};
}

/// run_in_chunks for a turtle::WorldServer that logs nowhere (tag's rounds, render's frames).
template <class Server>
Stopped run_server_in_chunks(Server& server, double until, std::uint64_t events_before, const Limits& limits,
                             Pace& pace, Clock::time_point start, Progress& progress, const std::string& doing) {
  Limits to = limits;
  to.until = until;
  return run_in_chunks(
      server.time(), events_before + server.world().stats().events, to, pace, start, progress, doing,
      [&](double t) {
        server.run_until(t);
        return events_before + server.world().stats().events;
      },
      [] {}, [](double, const std::string&) {}, [](double, std::uint64_t, bool, bool) {});
}

}  // namespace turtlegas::apps
