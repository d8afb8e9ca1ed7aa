// SPDX-License-Identifier: MIT
#include "run_loop.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <limits>


namespace turtlegas::apps {

StatusLine::StatusLine(bool enabled) : start_(Clock::now()), enabled_(enabled && ::isatty(STDERR_FILENO) != 0) {}

bool StatusLine::due() const {
  if (!enabled_) return false;
  const auto now = Clock::now();
  return now - start_ >= std::chrono::seconds(2) && now - last_ >= std::chrono::milliseconds(200);
}

void StatusLine::show(const std::string& text) {
  last_ = Clock::now();
  std::fprintf(stderr, "\r\033[K  %s ", text.c_str());
  std::fflush(stderr);
  shown_ = true;
}

void StatusLine::clear() {
  if (shown_) std::fputs("\r\033[K", stderr), std::fflush(stderr);
  shown_ = false;
}

Progress::Progress(double until) : until_(until), total_(until) {}

void Progress::set_part(double until, double offset, double total) {
  until_ = until;
  offset_ = offset;
  total_ = total;
}

std::string eta_text(double done, double total, double seconds) {
  const double sim_rate = seconds > 0.0 ? done / seconds : 0.0;
  return "ETA " + (sim_rate > 0.0 ? human_duration((total - done) / sim_rate) : std::string("unknown"));
}

void Progress::update(double t, std::uint64_t events, const std::string& doing) {
  if (!line_.due()) return;
  const auto now = Clock::now();
  const double done = offset_ + t;
  if (!line_.shown()) done0_ = done, events0_ = events, since_ = now;  // rates from the first line on
  const double span = std::chrono::duration<double>(now - since_).count();
  const double pct = total_ > 0.0 ? 100.0 * done / total_ : 100.0;
  const double rate = span > 0.0 ? static_cast<double>(events - events0_) / span : 0.0;
  const std::string eta = eta_text(done - done0_, total_ - done0_, span);
  char text[512];
  std::snprintf(text, sizeof text, "%st = %.6g / %.6g s  %5.1f%%  %.3g events/s  %s", doing.c_str(), t, until_, pct,
                rate, eta.c_str());
  line_.show(text);
}

Pace first_pace(SceneScales scales, const sim::World& world, double natural) {
  scales.set_cell(world.cell_size());
  double first = natural;
  if (scales.events_per_second > 0.0) first = std::min(first, 0x1p14 / scales.events_per_second);
  return {std::max(first, std::numeric_limits<double>::denorm_min())};
}

void finish_run(formats::RunFigures& run, const sim::World& world, const turtle::WorldServer* server,
                const sim::Overlap& sampled) {
  if (server)
    for (std::size_t i = 0; i < server->turtle_count(); ++i) run.turtles_finished += server->turtle(i).finished ? 1 : 0;
  for (std::size_t i = 0; i < world.ball_count(); ++i) run.balls_alive += world.ball(i).alive ? 1 : 0;
  run.energy_end = world.energy();
  const sim::Overlap now = world.measure_overlap(), seen = world.max_contact_overlap();
  run.max_overlap = std::max({now.depth, seen.depth, sampled.depth});
  run.max_overlap_relative = std::max({now.relative, seen.relative, sampled.relative});
}

const char* stop_name(Stopped s) {
  switch (s.first) {
    case Stop::until: return "";
    case Stop::signal: return signal_name(s.second);
    case Stop::max_wall_seconds: return "max-wall-seconds";
    case Stop::max_events: return "max-events";
  }
  return "";
}

int exit_code_for(Stopped s) {
  if (s.first == Stop::until) return exit_ok;
  return s.first == Stop::signal ? exit_code_for(s.second) : exit_limit;
}

void LimitOptions::add_to(CLI::App& cmd, const std::string& what, const std::string& written, const std::string& ends) {
  wall_option = cmd.add_option(
                       "--max-wall-seconds", max_wall_seconds,
                       "Stop " + what + " cleanly after this much wall-clock time, " + written + " (" + ends + ")")
                    ->check(real_in(0, 1e9, "seconds", true));
  events_option = cmd.add_option("--max-events", max_events,
                                 "Stop " + what + " cleanly once the engine has taken this many events, " + written +
                                     " (" + ends + ")")
                      ->check(integer_in(1, std::numeric_limits<std::int64_t>::max(), "events"));
}

std::optional<double> LimitOptions::wall_seconds() const {
  if (wall_option && *wall_option) return max_wall_seconds;
  return std::nullopt;
}

std::optional<std::uint64_t> LimitOptions::events() const {
  if (events_option && *events_option) return max_events;
  return std::nullopt;
}

}  // namespace turtlegas::apps
