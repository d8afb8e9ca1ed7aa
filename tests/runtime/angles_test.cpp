// SPDX-License-Identifier: MIT
// The conversions of sim/angles.hpp as the runtime, the loader and the writers use them: wraps
// into [0, 360) (touch bearings, the API's heading, draw builders), and the Logo heading vectors.
// (Here rather than in tests/sim: everything outside the engine converts through this header.)
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "turtlegas/sim/angles.hpp"

using namespace turtlegas;

TEST_CASE("wrap_degrees lands in [0, 360) for every angle, tiny negatives included", "[runtime][angles]") {
  // -1e-17 + 360 rounds to 360: a wrap that only adds 360 to a negative angle returns 360, which
  // Touch::bearing promises never to be.
  for (double a : {-1e-17, -1e-14, -0x1p-1074, -360.0 * std::numeric_limits<double>::epsilon() / 4, -720.0 - 1e-13,
                   -360.0, -1e300, 1e300, 720.0, 359.99999999999994, -0.0}) {
    CAPTURE(a);
    const double w = sim::wrap_degrees(a);
    CHECK(w >= 0.0);
    CHECK(w < 360.0);
  }
  CHECK(sim::wrap_degrees(-1e-17) == 0.0);
  CHECK(sim::wrap_degrees(-90.0) == 270.0);
  CHECK(sim::wrap_degrees(450.0) == 90.0);
  CHECK(sim::wrap_degrees(-450.0) == 270.0);
  CHECK(sim::wrap_degrees(1080.5) == 360.5 - 360.0);
  // Against fmod, away from the rounding edge: the same value, bit for bit (the fast paths are
  // exact steps of 360 by Sterbenz's lemma). Seed 11.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> any(-5000.0, 5000.0);
  for (int k = 0; k < 100000; ++k) {
    const double a = any(rng);
    double r = std::fmod(a, 360.0);
    if (r < 0.0) r += 360.0;
    if (r >= 360.0) r = 0.0;
    INFO("seed 11, draw " << k << ", a = " << a);
    REQUIRE(sim::wrap_degrees(a) == r);
  }
}

TEST_CASE("heading_direction is exact at quarter turns, also just below a full turn", "[runtime][angles]") {
  CHECK(sim::heading_direction(0) == sim::Vec2{0, 1});
  CHECK(sim::heading_direction(90) == sim::Vec2{1, 0});
  CHECK(sim::heading_direction(-90) == sim::Vec2{-1, 0});
  CHECK(sim::heading_direction(540) == sim::Vec2{0, -1});
  // 0.1 + 0.2 - 0.3 is 5.5e-17 and 0.3 - 0.1 - 0.2 is -2.8e-17: the second must be heading 0.
  CHECK(sim::heading_direction(0.3 - 0.1 - 0.2) == sim::Vec2{0, 1});
  const sim::Vec2 d = sim::heading_direction(30);
  CHECK(d.x == Approx(0.5).epsilon(1e-15));
  CHECK(d.y == Approx(std::sqrt(3.0) / 2).epsilon(1e-15));
}

TEST_CASE("degrees and radians, and the heading of a direction", "[runtime][angles]") {
  CHECK(sim::to_radians(180.0) == std::acos(-1.0));
  CHECK(sim::heading_of({0, 1}) == 0.0);
  CHECK(sim::heading_of({1, 0}) == Approx(std::acos(-1.0) / 2));
  CHECK(sim::heading_of({-1, 0}) == Approx(-std::acos(-1.0) / 2));
  CHECK(sim::heading_unit(0.0) == sim::Vec2{0, 1});
}
