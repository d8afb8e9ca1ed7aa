// SPDX-License-Identifier: MIT
// The seeded generator of random scenes that the field tests (tests/sim/field_oracle.hpp) and the
// field benchmark (bench/field_toi_bench.cpp) draw from, so that both draw the same kinds of
// scene the same way. Here because both may include sim/ and neither may include the other
// (scripts/check_layers.py: bench/ and tests/ are siblings); the engine itself draws nothing.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

#include "turtlegas/sim/vec2.hpp"

namespace turtlegas::sim {

/// Doubles from std::mt19937_64 by hand (53 bits, the same on every standard library), given a
/// fixed seed: uniform, log-uniform, a sign, a direction.
struct SeededRng {
  std::mt19937_64 gen;
  explicit SeededRng(std::uint64_t seed) : gen(seed) {}
  double uniform(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(gen() >> 11) * 0x1.0p-53; }
  double log_uniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
  double sign() { return (gen() & 1) ? 1.0 : -1.0; }
  Vec2 direction() {
    const double phi = uniform(0.0, 6.283185307179586);
    return {std::cos(phi), std::sin(phi)};
  }
  /// magnitude() * direction(), the direction drawn first. Scenes must not be drawn as
  /// `rng.uniform(...) * rng.direction()`: the order in which an overloaded operator's operands
  /// are evaluated is unspecified, g++ takes the right one first and clang++ the left, so the two
  /// compilers drew different random scenes. This keeps g++'s order, the one the tests were
  /// written and tuned with.
  template <class Magnitude>
  Vec2 direction_then(Magnitude magnitude) {
    const Vec2 d = direction();
    return magnitude() * d;
  }
};

}  // namespace turtlegas::sim
