// SPDX-License-Identifier: MIT
// The engine's memory for large arrays (sim/src/engine/big_memory.hpp): blocks of 8 MiB and more
// start on a 2 MiB boundary (where a huge page can back them), smaller ones keep their type's
// alignment, and every byte asked for is there. Whether the system really backs a block with
// huge pages is its own business (a hint); the speed it buys is measured in docs/performance.md.
#include <catch2/catch.hpp>

#include <cstdint>
#include <cstring>
#include <vector>

#include "engine/big_memory.hpp"

using namespace turtlegas::sim::detail;

namespace {
std::uintptr_t address(const void* p) { return reinterpret_cast<std::uintptr_t>(p); }
}  // namespace

TEST_CASE("large blocks start on a huge page, small ones keep their alignment", "[memory]") {
  const std::size_t mib = std::size_t{1} << 20;
  for (std::size_t bytes : {8 * mib, 8 * mib + 1, 128 * mib + 12345}) {
    void* p = allocate_big(bytes, 64);
    REQUIRE(p != nullptr);
    CHECK(address(p) % (2 * mib) == 0);
    std::memset(p, 0xAB, bytes);  // every byte is there (ASan and the kernel would object)
    CHECK(static_cast<unsigned char*>(p)[bytes - 1] == 0xAB);
    free_big(p);
  }
  for (std::size_t bytes : {std::size_t{0}, std::size_t{1}, std::size_t{128}, 8 * mib - 1}) {
    void* p = allocate_big(bytes, 64);
    REQUIRE(p != nullptr);
    CHECK(address(p) % 64 == 0);
    std::memset(p, 0, bytes);
    free_big(p);
  }
}

TEST_CASE("a vector on BigAllocator holds what it is given", "[memory]") {
  std::vector<std::uint32_t, BigAllocator<std::uint32_t>> v;
  v.assign(3'000'000, 7u);  // 12 MB: the huge-page path
  CHECK(address(v.data()) % (std::size_t{2} << 20) == 0);
  v.back() = 9u;
  std::vector<std::uint32_t, BigAllocator<std::uint32_t>> w(v);
  CHECK(w.size() == 3'000'000);
  CHECK(w.front() == 7u);
  CHECK(w.back() == 9u);
}
