// SPDX-License-Identifier: MIT
#include "event_queue.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

namespace turtlegas::sim::detail {

void EventQueue::reset(Node* first, std::size_t stride, std::size_t ids) {
  nodes_ = first;
  stride_ = stride;
  ids_ = ids;
  std::size_t buckets = 1024;
  while (buckets < ids) buckets *= 2;
  year_ = buckets;
  year_d_ = static_cast<double>(buckets);
  bucket_head_.assign(buckets, kAbsent);
  heap_.clear();
  overflow_head_ = kAbsent;
  finite_ = 0;
  t0_ = 0.0;
  width_ = 0.0;  // set at the first rebuild
  current_ = 0;
}

void EventQueue::push_list(std::uint32_t& head, std::uint32_t id, std::uint32_t where) {
  Node& n = node(id);
  n.where = where;
  n.prev = kAbsent;
  n.next = head;
  if (head != kAbsent) node(head).prev = id;
  head = id;
}

void EventQueue::insert(std::uint32_t id) {
  Node& n = node(id);
  if (!(n.key < std::numeric_limits<double>::infinity())) {
    n.where = kInfinite;
    return;
  }
  ++finite_;
  if (width_ == 0.0) {
    // No calendar yet: everything waits in the overflow until the first serve builds one.
    push_list(overflow_head_, id, kInOverflow);
    return;
  }
  const std::uint64_t b = bucket_of(n.key);
  if (b <= current_) heap_push(id);
  else if (b >= year_) push_list(overflow_head_, id, kInOverflow);
  else push_list(bucket_head_[b], id, static_cast<std::uint32_t>(b));
}

void EventQueue::unlink(std::uint32_t id) {
  Node& n = node(id);
  switch (n.where) {
    case kNowhere: return;
    case kInfinite: break;
    case kInHeap:
      heap_erase(n.prev);
      --finite_;
      break;
    default: {
      std::uint32_t& head = n.where == kInOverflow ? overflow_head_ : bucket_head_[n.where];
      if (n.prev != kAbsent) node(n.prev).next = n.next;
      else head = n.next;
      if (n.next != kAbsent) node(n.next).prev = n.prev;
      --finite_;
    }
  }
  n.where = kNowhere;
}

void EventQueue::set(std::uint32_t id, double key) {
  Node& n = node(id);
  if (n.where == kInHeap && n.prev == 0) {
    // The id just served gets its next key: the common case. Moved down from the root in place
    // when the key stays in the bucket being served, else taken off the root and filed.
    if ((key - t0_) * inv_width_ < served_end_) {  // bucket_of(key) <= current_ (and key finite)
      n.key = key;
      heap_down(0);
      return;
    }
    const std::uint32_t last = heap_.back();
    heap_.pop_back();
    if (last != id) {
      heap_place(0, last);
      heap_down(0);
    }
    --finite_;
    n.where = kNowhere;
  } else {
    unlink(id);
  }
  n.key = key;
  insert(id);
}

void EventQueue::remove(std::uint32_t id) { unlink(id); }

void EventQueue::refill() {
  while (heap_.empty()) {
    if (width_ == 0.0 || current_ + 1 >= year_) {
      // End of the year (or no calendar yet): rebuild around the earliest key.
      rebuild();
      continue;
    }
    ++current_;
    served_end_ = static_cast<double>(current_ + 1);
    // Move the next bucket into the heap.
    std::uint32_t id = bucket_head_[current_];
    bucket_head_[current_] = kAbsent;
    while (id != kAbsent) {
      const std::uint32_t next = node(id).next;
      heap_push(id);
      id = next;
    }
  }
}

void EventQueue::rebuild() {
  // Mark every stored id and find the earliest key, then lay a new calendar from there whose year
  // spans the bulk of them and insert the marked ids in id order. Marking in place rather than
  // gathering the ids in a list keeps the rebuild free of a per-body temporary (4 bytes a body at
  // the engine's peak).
  std::size_t count = 0;
  double start = std::numeric_limits<double>::infinity();
  for (std::uint32_t id = 0; id < ids_; ++id) {
    Node& n = node(id);
    if (n.where == kNowhere || n.where == kInfinite) continue;
    n.where = kRebuilding;
    ++count;
    start = std::min(start, n.key);
  }
  double sum = 0.0;
  for (std::uint32_t id = 0; id < ids_; ++id)
    if (node(id).where == kRebuilding) sum += node(id).key - start;
  std::fill(bucket_head_.begin(), bucket_head_.end(), kAbsent);
  heap_.clear();
  overflow_head_ = kAbsent;
  finite_ = 0;
  // Each id holds one pending event, on average (sum / n) ahead; the queue serves about
  // n / (sum / n) events per second, so this width gives a few events per bucket and a year
  // of about four mean look-aheads.
  const double n = static_cast<double>(count);
  double mean_ahead = n > 0 ? sum / n : 0.0;
  // Unless a few keys far beyond the rest set the mean alone (a charged gas: a slow ball whose
  // small circle never leaves its cell re-plans 2^30 periods ahead, 6.7e9 s, among keys of about
  // a second; ten such made the mean 10^7 s, every key fell into the bucket being served, and its
  // heap held them all). When the mean is over 64 times the median look-ahead (known to a binade,
  // from the exponent bits of every 16th id's when there are many), the mean is taken again
  // without the keys over 2^12 times the median, which wait in the overflow. Only the buckets
  // change, never the order of service; gases of straight flights (mean within a few medians)
  // keep their width to the bit.
  std::array<std::uint32_t, 2048> binade{};
  std::size_t sampled = 0;
  const std::uint32_t step = count >= 4096 ? 16 : 1;
  for (std::uint32_t id = 0; id < ids_; id += step)
    if (node(id).where == kRebuilding) {
      ++binade[(std::bit_cast<std::uint64_t>(node(id).key - start) >> 52) & 0x7FF];  // >= 0
      ++sampled;
    }
  std::size_t below = 0;
  int median_binade = 0;
  while (median_binade < 2047 && (below += binade[median_binade]) < (sampled + 1) / 2) ++median_binade;
  const double median_bound = std::ldexp(1.0, median_binade - 1023 + 1);  // above the median
  if (sampled > 0 && mean_ahead > 64.0 * median_bound) {
    const double cut = 4096.0 * median_bound;
    double kept_sum = 0.0, kept = 0.0;
    for (std::uint32_t id = 0; id < ids_; ++id)
      if (node(id).where == kRebuilding && node(id).key - start <= cut) {
        kept_sum += node(id).key - start;
        kept += 1.0;
      }
    if (kept > 0.0) mean_ahead = kept_sum / kept;
  }
  width_ = mean_ahead > 0.0 ? 4.0 * mean_ahead / static_cast<double>(year_) : 1.0;
  if (!(width_ > 0.0) || !std::isfinite(width_)) width_ = 1.0;
  inv_width_ = 1.0 / width_;
  t0_ = start;
  current_ = 0;
  served_end_ = 1.0;
  for (std::uint32_t id = 0; id < ids_; ++id) {
    if (node(id).where != kRebuilding) continue;
    node(id).where = kNowhere;
    insert(id);
  }
}

void EventQueue::shift_keys(double dt) {
  for (std::uint32_t id = 0; id < ids_; ++id)
    if (node(id).where != kNowhere) node(id).key -= dt;
  if (finite_ > 0) rebuild();
}

void EventQueue::heap_push(std::uint32_t id) {
  node(id).where = kInHeap;
  heap_.push_back(id);
  heap_up(static_cast<std::uint32_t>(heap_.size() - 1));
}

void EventQueue::heap_erase(std::uint32_t pos) {
  const std::uint32_t last = heap_.back();
  heap_.pop_back();
  if (pos == heap_.size()) return;
  heap_place(pos, last);
  heap_up(pos);
  heap_down(node(last).prev);
}

void EventQueue::heap_up(std::uint32_t pos) {
  const std::uint32_t id = heap_[pos];
  while (pos > 0) {
    const std::uint32_t parent = (pos - 1) / 2;
    if (!heap_before(id, heap_[parent])) break;
    heap_place(pos, heap_[parent]);
    pos = parent;
  }
  heap_place(pos, id);
}

void EventQueue::heap_down(std::uint32_t pos) {
  const std::uint32_t id = heap_[pos];
  const auto n = static_cast<std::uint32_t>(heap_.size());
  for (;;) {
    std::uint32_t child = 2 * pos + 1;
    if (child >= n) break;
    if (child + 1 < n && heap_before(heap_[child + 1], heap_[child])) ++child;
    if (!heap_before(heap_[child], id)) break;
    heap_place(pos, heap_[child]);
    pos = child;
  }
  heap_place(pos, id);
}

std::size_t EventQueue::memory_bytes() const {
  return bucket_head_.capacity() * sizeof(std::uint32_t) +
         heap_.capacity() * sizeof(std::uint32_t);
}

}  // namespace turtlegas::sim::detail
