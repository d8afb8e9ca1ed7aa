// SPDX-License-Identifier: MIT
// The records layout: what the engine keeps per body, one 128-byte record each.
#pragma once

#include <cstdint>
#include <limits>
#include <new>

#include "../event_queue.hpp"
#include "turtlegas/sim/toi.hpp"

namespace turtlegas::sim::detail {

inline constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

namespace {

/// One ball's state at its own local time t, kept in one cache line for the neighbour scans.
/// (Aligned, so that a body never straddles two lines: the heap gives only 16-byte alignment.)
struct alignas(64) Body {
  Vec2 x;
  Vec2 v;
  double t = 0.0;
  double r = 0.0;
  std::uint32_t count = 0;  ///< bumped whenever the ball changes course
  std::uint32_t cell = kNone;  ///< kNone once the ball has exited
  std::uint32_t next = kNone;  ///< cell list links
  std::uint32_t prev = kNone;
};
static_assert(sizeof(Body) == 64);

/// What a prediction is about. `body` partners are balls or turtles (ids are shared). (The end of a
/// turtle's own command is kept apart: Engine::end_.)
enum class Partner : std::uint8_t { none, body, wall, end, moving_end };

/// The earliest predicted collision of a ball, and when it leaves its cell (exact mode); aligned
/// so that it sits in one cache line.
struct alignas(32) Pending {
  double t_coll = kNever;
  double t_cross = kNever;
  std::uint32_t partner = 0;
  std::uint32_t partner_count = 0;
  std::uint32_t last = kNone;  ///< who the body collided with last (last_code), in the padding
  Partner kind = Partner::none;
  std::uint8_t cross_dir = 0;  ///< 0: -x, 1: +x, 2: -y, 3: +y
};
static_assert(sizeof(Pending) == 32);

/// Everything an event reads and writes about its own body, in two adjacent cache lines: serving a
/// body costs one pair of lines instead of a miss in each of four arrays (bodies, predictions,
/// queue nodes, masses) once they outgrow the cache. The four arrays took the same 128 bytes (and
/// `last_` 4 more, now in the padding of `Pending`).
struct alignas(64) Record {
  Body body;
  Pending pending;
  EventQueue::Node node;
  /// A ball's mass. A turtle has none (a ball meets it as a wall of infinite mass): its slot holds
  /// the internal time its command ends (kNever: no command running), which each of its events
  /// reads beside its prediction.
  double mass_or_end = 0.0;
};
static_assert(sizeof(Record) == 128);

/// One field of every record, indexed like the array it replaces.
template <class T, T& (*Field)(Record&)>
class Column {
 public:
  Column() = default;
  Column(Record* first, std::size_t n) : first_(first), n_(n) {}
  T& operator[](std::size_t i) const { return Field(first_[i]); }
  std::size_t size() const { return n_; }

 private:
  Record* first_ = nullptr;
  std::size_t n_ = 0;
};
inline Body& body_of(Record& r) { return r.body; }
inline Pending& pending_of(Record& r) { return r.pending; }
inline double& mass_of(Record& r) { return r.mass_or_end; }
inline double& command_end_of(Record& r) { return r.mass_or_end; }
inline std::uint32_t& last_of(Record& r) { return r.pending.last; }

struct FreeRecords {
  void operator()(Record* p) const { ::operator delete(p, std::align_val_t{alignof(Record)}); }
};

// Who a body collided with last, packed as kind << 29 | index: with straight relative motion a
// pair that has just collided cannot meet again before one of them has another event, so the
// prediction skips it rather than trusting the sign of a round-off-sized approach speed.
constexpr std::uint32_t last_code(Partner k, std::uint32_t index) {
  return (static_cast<std::uint32_t>(k) << 29) | index;
}

}  // namespace
}  // namespace turtlegas::sim::detail
