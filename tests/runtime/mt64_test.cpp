// SPDX-License-Identifier: MIT
// The turtles' generator (turtle_runtime/src/mt64.hpp) must be std::mt19937_64 word for word:
// worlds written before it replaced the standard engine keep their event logs.
#include <catch2/catch.hpp>

#include <cstdint>
#include <random>

#include "mt64.hpp"

using turtlegas::turtle::detail::Mt64;

TEST_CASE("Mt64 draws the same words as std::mt19937_64", "[runtime][rng]") {
  // Seeds as the server makes them (world seed ^ a hash of the id), the standard's default, 0 and
  // all ones; 2,000 draws cross six regenerations of the state.
  const std::uint64_t seeds[] = {5489u, 0u, ~std::uint64_t{0}, 0x9E3779B97F4A7C15u, 1u ^ 0xcbf29ce484222325u};
  for (const std::uint64_t seed : seeds) {
    std::mt19937_64 reference(seed);
    Mt64 mine;
    mine.seed_with(seed);
    for (int k = 0; k < 2000; ++k) {
      INFO("seed " << seed << ", draw " << k);
      REQUIRE(mine() == reference());
    }
  }
}

TEST_CASE("Mt64's 10,000th word is the one the standard fixes", "[runtime][rng]") {
  // [rand.predef]: the 10000th consecutive invocation of a default-constructed mt19937_64.
  Mt64 g;
  std::uint64_t last = 0;
  for (int k = 0; k < 10000; ++k) last = g();
  CHECK(last == 9981545732273789042ull);
}

TEST_CASE("Mt64::next_address names the word the next draw reads", "[runtime][rng]") {
  Mt64 g(7);
  const void* first = g.next_address();  // the state is regenerated first: word 0
  g();
  const auto* a = static_cast<const std::uint64_t*>(first);
  CHECK(g.next_address() == a + 1);
  for (std::size_t k = 1; k < Mt64::kN; ++k) g();
  CHECK(g.next_address() == a);  // all 312 used: the next draw regenerates and reads word 0
}
