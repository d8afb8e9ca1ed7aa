// SPDX-License-Identifier: MIT
// The records layout: what the engine keeps per body, one 128-byte record each (Body, Pending,
// the queue node and the mass), and Column, which views one field of every record as an array.
// The layout is measured (docs/performance.md, "one 128-byte record per body"): keep the sizes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <new>

#include "../event_queue.hpp"
#include "turtlegas/sim/toi.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim::detail {

inline constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

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
/// turtle's own command is kept apart: BodyStore::end.)
enum class Partner : std::uint8_t { none, body, wall, end, moving_end };

/// Who a body collided with last: a partner's kind and index packed in 32 bits (they fit in the
/// padding of Pending). With straight relative motion a pair that has just collided cannot meet
/// again before one of them has another event, so the prediction skips it rather than trusting
/// the sign of a round-off-sized approach speed (the contacts room's rule: contacts/contacts.hpp,
/// just_met and skip; whether the motion is straight is the flight's call: flights.hpp).
class LastPartner {
 public:
  /// The index takes the low 29 bits, the kind the top 3. validate() keeps every index a scene
  /// can produce (bodies; walls, wall ends and moving-wall ends, two per wall) below
  /// kMaxObjects, and add_wall() keeps the walls added at run time there too.
  static constexpr int kIndexBits = 29;
  static_assert(kMaxObjects == std::size_t{1} << kIndexBits, "validate()'s bound is this packing's");
  static_assert(static_cast<std::uint32_t>(Partner::moving_end) < (1u << (32 - kIndexBits)),
                "every Partner fits in the top bits");

  constexpr LastPartner() = default;
  static constexpr LastPartner of(Partner kind, std::uint32_t index) {
    return LastPartner{(static_cast<std::uint32_t>(kind) << kIndexBits) | index};
  }
  static constexpr LastPartner none() { return LastPartner{}; }
  bool is_none() const { return code_ == kNone; }
  /// Meaningful only when not none().
  Partner kind() const { return static_cast<Partner>(code_ >> kIndexBits); }
  std::uint32_t index() const { return code_ & ((1u << kIndexBits) - 1); }
  bool operator==(const LastPartner&) const = default;
  /// The packed bits, and a LastPartner from them (a saved engine state, saved_state.hpp).
  std::uint32_t code() const { return code_; }
  static constexpr LastPartner from_code(std::uint32_t code) { return LastPartner{code}; }

 private:
  explicit constexpr LastPartner(std::uint32_t code) : code_(code) {}
  std::uint32_t code_ = kNone;
};
static_assert(sizeof(LastPartner) == 4);

/// The earliest predicted collision of a ball, and when it leaves its cell (exact mode); aligned
/// so that it sits in one cache line.
struct alignas(32) Pending {
  double t_coll = kNever;
  double t_cross = kNever;
  std::uint32_t partner = 0;
  std::uint32_t partner_count = 0;
  LastPartner last;  ///< who the body collided with last, in the padding
  Partner kind = Partner::none;
  std::uint8_t cross_dir = 0;  ///< 0: -x, 1: +x, 2: -y, 3: +y

  /// The candidate becomes the prediction (the caller has checked that it is earlier). A body
  /// partner's count is kept, so that a change of its course makes the prediction stale.
  void take(double t, Partner k, std::uint32_t index) {
    t_coll = t;
    kind = k;
    partner = index;
  }
  void take(double t, Partner k, std::uint32_t index, std::uint32_t count) {
    take(t, k, index);
    partner_count = count;
  }
};
static_assert(sizeof(Pending) == 32);

/// Everything an event reads and writes about its own body, in two adjacent cache lines: serving a
/// body costs one pair of lines instead of a miss in each of four arrays (bodies, predictions,
/// queue nodes, masses) once they outgrow the cache. The four arrays took the same 128 bytes (and
/// the last partner 4 more, now in the padding of `Pending`). Whatever a flight needs per ball
/// beyond this (a charge-to-mass ratio, a species) lives in the flight, allocated only for the
/// scenes that use it (flights.hpp).
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
inline LastPartner& last_of(Record& r) { return r.pending.last; }

/// The records' memory: n records, aligned to their cache lines, on huge pages when large
/// (big_memory.hpp). Freed by FreeRecords.
Record* allocate_records(std::size_t n);
struct FreeRecords {
  void operator()(Record* p) const;
};

}  // namespace turtlegas::sim::detail
