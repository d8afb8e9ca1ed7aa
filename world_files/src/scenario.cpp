// SPDX-License-Identifier: MIT
#include "turtlegas/world/scenario.hpp"

#include <algorithm>
#include <cstdint>
#include <memory>
#include <stdexcept>

#include "turtlegas/sim/format.hpp"

namespace turtlegas::world {
namespace {

std::string num(double v) { return sim::format_number(v); }

}  // namespace

ExpectResult run_expectations(const Scene& scene, const turtle::Registry& registry, sim::Mode mode,
                              turtle::ServerOptions options) {
  const sim::WorldDef& def = scene.def;
  const Expectations& expect = scene.expect;
  if (!expect.until) throw std::invalid_argument("the scene's expect list has no {\"until\": T}");
  const double until = *expect.until;
  options.mode = mode;
  // With the scene's game, so that {"it": ...} sees it played.
  const std::unique_ptr<turtle::WorldServer> played = make_server(scene, registry, options);
  turtle::WorldServer& server = *played;
  std::vector<turtle::LogEvent> log;
  server.set_event_log(&log);
  const RunView view(server, def);

  std::vector<std::unique_ptr<Check>> checks;
  std::vector<double> times;
  for (const auto& entry : expect.entries) {
    checks.push_back(entry.assertion->start(view));
    for (double t : entry.assertion->sample_times())
      if (t <= until) times.push_back(t);
  }
  // Every control step boundary, as the server computes it (k dt), then the end.
  for (std::uint64_t k = 1;; ++k) {
    const double t = static_cast<double>(k) * def.dt;
    if (!(t < until)) break;
    times.push_back(t);
  }
  times.push_back(until);
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());

  ExpectResult result;
  result.assertions = checks.size();
  for (auto& c : checks) c->on_step(view);
  try {
    for (double t : times) {
      if (t <= 0.0) continue;
      server.run_until(t);
      for (const turtle::LogEvent& e : log)
        for (auto& c : checks) c->on_event(e, view);
      log.clear();
      for (auto& c : checks) c->on_step(view);
    }
  } catch (const turtle::BusyLoopError& e) {
    server.set_event_log(nullptr);
    result.failures.push_back("the run stopped at t = " + num(server.time()) + ": " + e.what());
    return result;
  }
  server.set_event_log(nullptr);
  for (std::size_t i = 0; i < checks.size(); ++i)
    if (auto failure = checks[i]->finish(view))
      result.failures.push_back("expect[" + std::to_string(expect.entries[i].index) + "] " + *failure);
  return result;
}

}  // namespace turtlegas::world
