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
                              turtle::ServerOptions options, const ExpectHooks& hooks) {
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
  if (hooks.on_start) hooks.on_start(server);

  std::vector<std::unique_ptr<Check>> checks;
  // The times to stop at: every assertion's sample time and every control step boundary (k dt,
  // as the server computes it), then the end. The step boundaries are generated as the run goes,
  // not stored: a dt of 1e-9 over until 100 is 1e11 of them (test-tiny-dt-oom.json).
  std::vector<double> samples;
  for (const auto& entry : expect.entries) {
    checks.push_back(entry.assertion->start(view));
    for (double t : entry.assertion->sample_times())
      if (t > 0.0 && t < until) samples.push_back(t);
  }
  std::sort(samples.begin(), samples.end());
  samples.erase(std::unique(samples.begin(), samples.end()), samples.end());

  ExpectResult result;
  result.assertions = checks.size();
  for (auto& c : checks) c->on_step(view);
  try {
    auto step = [&](double t) {
      server.run_until(t);
      for (const turtle::LogEvent& e : log)
        for (auto& c : checks) c->on_event(e, view);
      log.clear();
      for (auto& c : checks) c->on_step(view);
      if (hooks.on_step) hooks.on_step(server);
    };
    std::size_t next_sample = 0;
    for (std::uint64_t k = 1; until > 0.0; ++k) {
      const double boundary = static_cast<double>(k) * def.dt;
      const double t = std::min(boundary, until);
      for (; next_sample < samples.size() && samples[next_sample] < t; ++next_sample) step(samples[next_sample]);
      if (next_sample < samples.size() && samples[next_sample] == t) ++next_sample;
      step(t);
      if (!(boundary < until)) break;
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
