// SPDX-License-Identifier: MIT
// The control-step grid, defined once (sim/control_steps.hpp): boundary k is k * dt, and the next
// boundary after t is the first of those strictly after t, whatever the rounding of t / dt.
#include <catch2/catch.hpp>

#include <cmath>

#include "turtlegas/sim/control_steps.hpp"

using namespace turtlegas::sim;

TEST_CASE("control boundaries are k * dt, and the next one is strictly after t", "[control]") {
  for (double dt : {1.0 / 30.0, 0.1, 0.25, 1e-3, 7.0}) {
    INFO("dt " << dt);
    for (std::uint64_t k = 0; k < 5000; ++k) {
      const double tk = control_boundary(k, dt);
      REQUIRE(tk == static_cast<double>(k) * dt);
      // At a boundary: the next one is k + 1 (the old engine's floor(t/dt + 1e-9) + 1 agreed here
      // only thanks to its fudge; the runtime's k * dt and the engine now share this one rule).
      REQUIRE(next_control_step(tk, dt) == k + 1);
      // Just before it: k itself, however close.
      const double before = std::nextafter(tk, -1.0);
      if (k > 0) REQUIRE(next_control_step(before, dt) == k);
      // Just after it: k + 1.
      REQUIRE(next_control_step(std::nextafter(tk, 1e300), dt) == k + 1);
    }
  }
  CHECK(next_control_step(0.0, 0.1) == 1);
  CHECK(next_control_step(0.05, 0.1) == 1);
}
