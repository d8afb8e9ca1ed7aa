// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace turtlegas::sim::detail {

/// The event queue of exact mode: one key per body (the time of its next event), served in
/// (key, id) order so that simultaneous events are deterministic.
///
/// A calendar queue after Paul (J. Comput. Phys. 221, 2007): keys fall into time buckets of width
/// w; only the bucket being served is kept ordered, in a small binary heap, and the others are
/// unordered linked lists, so insertion and removal are O(1) and serving costs O(log of the
/// bucket's size). Keys beyond the calendar's year wait in an overflow list; at the end of each
/// year the calendar is rebuilt around the keys it holds, with w re-estimated so that a bucket
/// holds a few events. Infinite keys (no event) are tracked but never stored.
class EventQueue {
 public:
  static constexpr std::uint32_t kAbsent = std::numeric_limits<std::uint32_t>::max();

  /// Where the queue keeps one id's key and links. The nodes live in the caller's per-body
  /// records (next to the body's other hot state, so that serving an id touches one record
  /// rather than several arrays); the queue reaches node `id` at `stride * id` bytes past the first.
  struct Node {
    double key = 0.0;
    std::uint32_t where = 0xFFFFFFF3u;  ///< bucket slot, or one of the k* states (kNowhere)
    std::uint32_t prev = kAbsent;       ///< list links, or the heap position when kInHeap
    std::uint32_t next = kAbsent;
  };

  /// Starts empty over `ids` nodes (default-constructed by the caller) at `first`, `stride` bytes
  /// apart; they must stay put while the queue is used.
  void reset(Node* first, std::size_t stride, std::size_t ids);
  /// The same nodes, moved to `first` by a copy of their records (World::copy): the queue's
  /// links are ids, so only where the nodes are changes.
  void rebind(Node* first) { nodes_ = first; }
  /// Inserts id or moves it to its new key (which may be infinite).
  void set(std::uint32_t id, double key);
  void remove(std::uint32_t id);
  /// True when no finite key is stored.
  bool empty() const { return finite_ == 0; }
  /// Whether id is in the queue (with a finite or an infinite key), and its key then: what a
  /// caller that rebuilds the queue over moved nodes (a run-time spawn) sets again. The order
  /// of service depends on the keys and ids alone (ties go to the smaller id), not on the
  /// buckets, so such a rebuild serves the same ids in the same order.
  bool contains(std::uint32_t id) const { return node(id).where != kNowhere; }
  double key(std::uint32_t id) const { return node(id).key; }
  /// The earliest (key, id); only when !empty().
  double top_key() { settle(); return node(heap_[0]).key; }
  std::uint32_t top_id() { settle(); return heap_[0]; }
  /// An id likely to be served soon after the top, k = 0 or 1 (the top's children in the served
  /// bucket, or the first id filed in the next bucket), or kAbsent; for prefetching.
  std::uint32_t next_id(std::size_t k) const {
    if (k + 1 < heap_.size()) return heap_[k + 1];
    if (k == 1 && current_ + 1 < year_) return bucket_head_[current_ + 1];
    return kAbsent;
  }
  /// Subtracts dt from every key (time rebasing) and rebuilds the calendar around them.
  void shift_keys(double dt);
  /// The queue's own arrays; the nodes are the caller's.
  std::size_t memory_bytes() const;

 private:
  /// Node::where beyond the bucket slots; kRebuilding marks the ids a rebuild re-inserts.
  enum : std::uint32_t { kInHeap = 0xFFFFFFF0u, kInOverflow, kInfinite, kNowhere, kRebuilding };
  static_assert(kNowhere == 0xFFFFFFF3u);

  Node& node(std::uint32_t id) const {
    return *reinterpret_cast<Node*>(reinterpret_cast<char*>(nodes_) + stride_ * id);
  }

  void insert(std::uint32_t id);
  void unlink(std::uint32_t id);
  void push_list(std::uint32_t& head, std::uint32_t id, std::uint32_t where);
  /// Makes heap_ hold the earliest key (it is empty only between buckets).
  void settle() {
    if (heap_.empty()) refill();
  }
  void refill();
  void rebuild();
  std::uint64_t bucket_of(double key) const {
    // Truncation is floor here: b is known to be >= 0 when it is converted.
    const double b = (key - t0_) * inv_width_;
    if (!(b >= 0.0)) return 0;
    if (b >= year_d_) return year_;
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(b));
  }

  // The small heap of the bucket being served.
  bool heap_before(std::uint32_t a, std::uint32_t b) const {
    const double ka = node(a).key, kb = node(b).key;
    return ka < kb || (ka == kb && a < b);
  }
  void heap_push(std::uint32_t id);
  void heap_erase(std::uint32_t pos);
  void heap_up(std::uint32_t pos);
  void heap_down(std::uint32_t pos);
  void heap_place(std::uint32_t pos, std::uint32_t id) {
    heap_[pos] = id;
    node(id).prev = pos;
  }

  Node* nodes_ = nullptr;
  std::size_t stride_ = sizeof(Node);
  std::size_t ids_ = 0;
  std::vector<std::uint32_t> bucket_head_;
  std::vector<std::uint32_t> heap_;
  std::uint32_t overflow_head_ = kAbsent;
  std::size_t finite_ = 0;
  double t0_ = 0.0;          ///< start of bucket 0 of this year
  double width_ = 1.0;       ///< bucket width, seconds
  double inv_width_ = 1.0;
  std::uint64_t current_ = 0;  ///< the bucket being served; keys before its end go to the heap
  std::uint64_t year_ = 0;     ///< number of buckets in a year
  double year_d_ = 0.0;        ///< the same, as a double
  double served_end_ = 1.0;    ///< current_ + 1, as a double: keys below t0_ + served_end_ w are served
};

}  // namespace turtlegas::sim::detail
