// SPDX-License-Identifier: MIT
#include "big_memory.hpp"

#include <algorithm>
#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace turtlegas::sim::detail {

namespace {
constexpr std::size_t kHugePage = std::size_t{2} << 20;
/// From this size on a block is laid on huge pages: below it the block fits the TLB's reach with
/// small pages anyway, and its last, partial huge page would be a large share of it.
constexpr std::size_t kHugeFrom = 4 * kHugePage;
}  // namespace

void* allocate_big(std::size_t bytes, std::size_t align) {
  bytes = std::max<std::size_t>(bytes, 1);
  const bool huge = bytes >= kHugeFrom;
  align = std::max({align, sizeof(void*), huge ? kHugePage : std::size_t{1}});
  void* p = nullptr;
  if (::posix_memalign(&p, align, bytes) != 0) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  // A hint, over the block's whole huge pages only, so that the resident size stays the block's
  // size (a huge page over the tail would add up to 2 MiB). Where the system has no huge pages
  // the call fails and the block stays on small pages: nothing else changes.
  if (huge) (void)::madvise(p, bytes / kHugePage * kHugePage, MADV_HUGEPAGE);
#endif
  return p;
}

void free_big(void* p) noexcept { std::free(p); }

}  // namespace turtlegas::sim::detail
