// SPDX-License-Identifier: MIT
// The body store: one Record per body (balls are ids [0, balls()), turtles after them), the
// columns that view the records as arrays, the bodies' collision layers, and the cell lists.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "big_memory.hpp"
#include "records.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim::detail {

class BodyStore {
 public:
  BodyStore() = default;
  /// Copies the bodies of def. `release`, when given, is def's own ball list: it is emptied and
  /// its memory freed as soon as the balls have been copied, so that the scene and the records
  /// never take memory at the same time (see the constructor). `with_layers`: keep the bodies'
  /// collision layers (scenes with extras).
  BodyStore(const WorldDef& def, std::vector<BallDef>* release, bool with_layers);
  /// A copy with records of its own (World::copy): the records' bytes, the columns pointed at
  /// them. The event queue that links the records must be rebound (EventQueue::rebind).
  BodyStore(const BodyStore& other);
  BodyStore& operator=(const BodyStore&) = delete;
  BodyStore(BodyStore&&) noexcept = default;  // the records stay where they are: the columns hold
  BodyStore& operator=(BodyStore&&) noexcept = default;

  std::uint32_t balls() const { return nb_; }
  /// Makes room for one body with id `at`: a ball at balls() (after the balls, before the
  /// turtles) or a turtle at size(). The records move to a new allocation one longer (the
  /// columns follow), the bodies from `at` on shift up by one id, and every id the records, the
  /// squeeze marks and the cell lists keep follows them, so that the relative order of all ids
  /// (which breaks ties in the queue) stays as it was. The new record is default (cell kNone,
  /// unlinked); its layers are the caller's to insert. Every queue node is left out of any queue: the caller resets the queue
  /// and sets the keys again (EventQueue::contains and key, read before). A run-time spawn (world_changes.hpp).
  void insert(std::uint32_t at, bool ball);
  std::size_t size() const { return body.size(); }
  /// The queue's nodes, one in each record (EventQueue::reset).
  EventQueue::Node* nodes() const { return size() > 0 ? &records_[0].node : nullptr; }
  EventQueue::Node& node_at(std::size_t i) const { return records_[i].node; }

  Column<Body, body_of> body;
  Column<double, mass_of> mass;         ///< balls only
  Column<double, command_end_of> end;   ///< turtles only: when the command running ends
  Column<LastPartner, last_of> last;
  Column<Pending, pending_of> pending;

  std::vector<Layers> layers;  ///< per body (with_layers only)

  /// The squeeze rule's mark (contacts/squeeze.hpp): the two obstacles a body was last held between, its
  /// course counter then, when, and whether it flies straight. The vector stays empty until a
  /// body is first held.
  struct Held {
    LastPartner a, b;
    std::uint32_t count = 0;
    std::uint32_t count_a = 0, count_b = 0;  ///< the obstacles' counters, when they are turtles
    bool straight = false;
    double t = 0.0;  ///< internal time of the squeeze
  };
  std::vector<Held> held;
  void hold(std::uint32_t i, LastPartner a, LastPartner b, double now, bool straight) {
    if (held.empty()) held.assign(size(), Held{});
    auto count_of = [&](LastPartner p) { return p.kind() == Partner::body ? body[p.index()].count : 0u; };
    held[i] = {a, b, body[i].count, count_of(a), count_of(b), straight, now};
  }
  /// Whether a contact of body i with `partner` predicted for internal time t is the round-off
  /// echo of a squeeze the rule has answered: the body has not changed course since, and either
  /// flies straight (leaving a line or a point at rate >= 0 in a straight line, it cannot approach
  /// it again: only round-off says it does) or the contact is at that very instant.
  bool held_against(std::uint32_t i, LastPartner partner, double t) const {
    if (held.empty()) return false;
    const Held& h = held[i];
    if (h.count != body[i].count || !(h.straight || h.t == t)) return false;
    // A turtle obstacle that has changed course since (a new command) can meet the body anew.
    if (h.a == partner) return partner.kind() != Partner::body || body[partner.index()].count == h.count_a;
    if (h.b == partner) return partner.kind() != Partner::body || body[partner.index()].count == h.count_b;
    return false;
  }
  /// A kick between steps, or a wall changing course at a keyframe, changes courses without a
  /// collision: no mark holds after it.
  void release_held() {
    for (Held& h : held) h.a = h.b = LastPartner::none();
  }
  /// Internal time moves by -shift (a rebase, or the end of a step).
  void shift_held(double shift) {
    for (Held& h : held) h.t -= shift;
  }
  bool layered = false;        ///< whether any body's layers differ from the defaults

  /// The cell lists: the balls, and the turtles, listed in each cell of the table.
  void make_lists(std::size_t cells, bool with_turtles) {
    head.assign(cells, kNone);
    if (with_turtles) turtle_head.assign(cells, kNone);
  }
  void link(std::uint32_t i, std::uint32_t cell, bool turtle) {
    Body& b = body[i];
    std::uint32_t& h = turtle ? turtle_head[cell] : head[cell];
    b.cell = cell;
    b.prev = kNone;
    b.next = h;
    if (b.next != kNone) body[b.next].prev = i;
    h = i;
  }
  void unlink(std::uint32_t i, bool turtle) {
    Body& b = body[i];
    if (b.prev != kNone) body[b.prev].next = b.next;
    else (turtle ? turtle_head[b.cell] : head[b.cell]) = b.next;
    if (b.next != kNone) body[b.next].prev = b.prev;
    b.next = b.prev = kNone;
  }
  std::vector<std::uint32_t, BigAllocator<std::uint32_t>> head;  ///< balls by cell (huge pages when large)
  std::vector<std::uint32_t> turtle_head;  ///< turtles by cell (only with extras)

 private:
  std::uint32_t nb_ = 0;
  std::unique_ptr<Record[], FreeRecords> records_;
};

}  // namespace turtlegas::sim::detail
