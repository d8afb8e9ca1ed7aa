// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace turtlegas::turtle::detail {

/// The standard's std::mt19937_64 ([rand.predef]: MT19937-64 with its fixed parameters and
/// seeding), word for word the same stream, written out so that the scheduler can see where the
/// next draw will read: with 10^4 turtles a turtle's 2.5 KB generator is cold when its program
/// resumes, and `next_address()` lets the draw's cache miss be asked for ahead of time. The index
/// comes first so that it shares a line with whatever precedes the generator.
class Mt64 {
 public:
  static constexpr std::size_t kN = 312;

  explicit Mt64(std::uint64_t seed = 5489u) { seed_with(seed); }

  void seed_with(std::uint64_t seed) {
    x_[0] = seed;
    for (std::size_t i = 1; i < kN; ++i) x_[i] = 6364136223846793005ull * (x_[i - 1] ^ (x_[i - 1] >> 62)) + i;
    p_ = kN;
  }

  std::uint64_t operator()() {
    if (p_ >= kN) twist();
    std::uint64_t y = x_[p_++];
    y ^= (y >> 29) & 0x5555555555555555ull;
    y ^= (y << 17) & 0x71D67FFFEDA60000ull;
    y ^= (y << 37) & 0xFFF7EEE000000000ull;
    y ^= y >> 43;
    return y;
  }

  /// The state word the next draw reads (the first, when the next draw regenerates the state).
  const void* next_address() const { return &x_[p_ < kN ? p_ : 0]; }

 private:
  void twist() {
    constexpr std::uint64_t kUpper = ~0ull << 31, kLower = ~kUpper, kA = 0xB5026F5AA96619E9ull;
    constexpr std::size_t kM = 156;
    for (std::size_t i = 0; i < kN; ++i) {
      const std::uint64_t y = (x_[i] & kUpper) | (x_[(i + 1) % kN] & kLower);
      x_[i] = x_[(i + kM) % kN] ^ (y >> 1) ^ ((y & 1u) != 0 ? kA : 0u);
    }
    p_ = 0;
  }

  std::size_t p_ = kN;
  std::array<std::uint64_t, kN> x_{};
};

}  // namespace turtlegas::turtle::detail
