// SPDX-License-Identifier: MIT
// Memory for the engine's large per-body and per-cell arrays: a block of several MB (the records
// and the cell lists of a gas of some 10^5 balls and more) is aligned to 2 MiB and asked to be
// backed by huge pages where the system offers them (Linux's transparent huge pages, `madvise`
// mode), so that the random reads of a big gas miss the TLB far less often (docs/performance.md,
// "Huge pages for the large arrays"). Smaller blocks are ordinary aligned allocations.
#pragma once

#include <cstddef>

namespace turtlegas::sim::detail {

/// bytes of memory aligned to at least `align` (a power of two); throws std::bad_alloc.
void* allocate_big(std::size_t bytes, std::size_t align);
void free_big(void* p) noexcept;

/// A standard allocator over allocate_big, for the engine's large vectors.
template <class T>
struct BigAllocator {
  using value_type = T;
  BigAllocator() = default;
  template <class U>
  BigAllocator(const BigAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(allocate_big(n * sizeof(T), alignof(T))); }
  void deallocate(T* p, std::size_t) noexcept { free_big(p); }
  template <class U>
  bool operator==(const BigAllocator<U>&) const noexcept { return true; }
};

}  // namespace turtlegas::sim::detail
