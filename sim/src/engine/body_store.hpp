// SPDX-License-Identifier: MIT
// The body store: one Record per body (balls are ids [0, balls()), turtles after them), the
// columns that view the records as arrays, the bodies' collision layers, and the cell lists.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

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

  std::uint32_t balls() const { return nb_; }
  std::size_t size() const { return body.size(); }
  /// The queue's nodes, one in each record (EventQueue::reset).
  EventQueue::Node* nodes() const { return size() > 0 ? &records_[0].node : nullptr; }

  Column<Body, body_of> body;
  Column<double, mass_of> mass;         ///< balls only
  Column<double, command_end_of> end;   ///< turtles only: when the command running ends
  Column<LastPartner, last_of> last;
  Column<Pending, pending_of> pending;

  std::vector<Layers> layers;  ///< per body (with_layers only)
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
  std::vector<std::uint32_t> head;         ///< balls by cell
  std::vector<std::uint32_t> turtle_head;  ///< turtles by cell (only with extras)

 private:
  std::uint32_t nb_ = 0;
  std::unique_ptr<Record[], FreeRecords> records_;
};

}  // namespace turtlegas::sim::detail
