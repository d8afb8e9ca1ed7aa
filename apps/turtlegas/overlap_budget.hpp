// SPDX-License-Identifier: MIT
// How often `run --stats` measures the deepest overlap (docs/cli.md, "The overlap self-check"):
// shared by the 2-D run (run_command.cpp) and the 3-D one (run3d.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace turtlegas::apps {

/// The instants at which a run may measure the deepest overlap when --overlap-samples does not say:
/// every control step of the run, at most 1000 of them. Which of them are measured is the
/// SampleBudget's to say.
inline std::uint64_t overlap_instants(double until, double dt) {
  const double steps = dt > 0.0 ? std::ceil(until / dt) : 1000.0;
  const double k = std::min(steps, 1000.0);
  return k >= 1.0 ? static_cast<std::uint64_t>(k) : 1;
}

/// Which of the default instants the self-check measures, so that it costs a bounded share of the
/// run (docs/cli.md, "The overlap self-check"): a measure costs about `cost` body-measures (each
/// body against its neighbours and the walls: bodies x (1 + walls/8)), and one is taken at an
/// instant only if the run has served kEventsPer events per body-measure taken so far, this one
/// included, beyond a small allowance (kAllowance body-measures, well under a millisecond) that
/// lets a small scene be measured at every instant. Counted in events, not in wall time, so that
/// the same run measures at the same instants every time: its stats are reproducible.
struct SampleBudget {
  /// A body-measure (~30-100 ns) against an event (~150-500 ns at N = 10^4 to 10^6): one per 4
  /// events keeps the measures near 5 % of the run (docs/performance.md, "What `--stats` costs").
  static constexpr std::uint64_t kEventsPer = 4;
  static constexpr std::uint64_t kAllowance = 4096;
  std::uint64_t cost = 0;
  bool unlimited = false;  ///< --overlap-samples given: every instant asked for is measured
  std::uint64_t taken = 0;

  SampleBudget(std::size_t bodies, std::size_t walls, bool every)
      : cost(std::max<std::uint64_t>(1, bodies + bodies * walls / 8)), unlimited(every) {}
  /// Whether to measure at an instant `events` events into the run; counts it if so.
  bool take(std::uint64_t events) {
    if (!unlimited && (taken + 1) * cost > kAllowance + events / kEventsPer) return false;
    ++taken;
    return true;
  }
};

}  // namespace turtlegas::apps
