// SPDX-License-Identifier: MIT
#include "body_store.hpp"

#include "big_memory.hpp"

#include <algorithm>
#include <cstring>
#include <new>
#include <type_traits>

namespace turtlegas::sim::detail {

Record* allocate_records(std::size_t n) {
  return static_cast<Record*>(allocate_big(std::max<std::size_t>(n, 1) * sizeof(Record), alignof(Record)));
}

void FreeRecords::operator()(Record* p) const { free_big(p); }

BodyStore::BodyStore(const WorldDef& def, std::vector<BallDef>* release, bool with_layers) {
  nb_ = static_cast<std::uint32_t>(def.balls.size());
  const std::size_t n = def.balls.size() + def.turtles.size();
  // The records first, then (for a consumed scene) free the ball list before anything else per
  // ball or per cell is allocated. While the scene is alive only what the records need from it
  // (48 bytes a ball) is written, packed at the records' far end, whose pages alone are touched;
  // once the scene is gone the records are laid out front to back over it (record i ends before
  // ball i + 1's packed data begins). So the peak is the scene plus 48 bytes a ball, not plus 128.
  struct Packed {
    Vec2 x, v;
    double r, mass;
  };
  static_assert(sizeof(Record) >= sizeof(Packed) && sizeof(Record) % alignof(Packed) == 0);
  records_.reset(allocate_records(n));
  char* const raw = reinterpret_cast<char*>(records_.get());
  char* const packed = raw + n * (sizeof(Record) - sizeof(Packed));
  if (with_layers) {
    layers.resize(n);
    for (std::uint32_t i = 0; i < nb_; ++i) layers[i] = def.balls[i].layers;
    for (std::size_t k = 0; k < def.turtles.size(); ++k) layers[nb_ + k] = def.turtles[k].layers;
    layered = std::any_of(layers.begin(), layers.end(), [](const Layers& l) { return l != Layers{}; });
  }
  for (std::uint32_t i = 0; i < nb_; ++i) {
    const BallDef& d = def.balls[i];
    new (packed + i * sizeof(Packed)) Packed{d.pos, d.vel, d.radius, d.mass};
  }
  if (release) std::vector<BallDef>().swap(*release);
  for (std::uint32_t i = 0; i < n; ++i) {
    Packed d{};
    if (i < nb_) std::memcpy(&d, packed + i * sizeof(Packed), sizeof(Packed));
    Record* rec = new (raw + i * sizeof(Record)) Record{};
    rec->body.x = d.x;
    rec->body.v = d.v;
    rec->body.r = d.r;
    rec->mass_or_end = d.mass;
  }
  body = {records_.get(), n};
  mass = {records_.get(), nb_};
  end = {records_.get(), n};
  last = {records_.get(), n};
  pending = {records_.get(), n};
  for (std::size_t k = 0; k < def.turtles.size(); ++k) {
    const TurtleDef& d = def.turtles[k];
    const auto id = static_cast<std::uint32_t>(nb_ + k);
    body[id].x = d.pos;
    body[id].r = d.radius;
    end[id] = kNever;
  }
}

BodyStore::BodyStore(const BodyStore& o)
    : layers(o.layers), held(o.held), layered(o.layered), head(o.head), turtle_head(o.turtle_head), nb_(o.nb_) {
  const std::size_t n = o.size();
  if (n > 0) {
    records_.reset(allocate_records(n));
    static_assert(std::is_trivially_copyable_v<Record>);
    std::memcpy(static_cast<void*>(records_.get()), o.records_.get(), n * sizeof(Record));
  }
  body = {records_.get(), n};
  mass = {records_.get(), nb_};
  end = {records_.get(), n};
  last = {records_.get(), n};
  pending = {records_.get(), n};
}

void BodyStore::insert(std::uint32_t at, bool ball) {
  const std::size_t n = size();
  auto up = [at](std::uint32_t id) { return id != kNone && id >= at ? id + 1 : id; };
  auto up_partner = [&](LastPartner p) {
    return !p.is_none() && p.kind() == Partner::body ? LastPartner::of(Partner::body, up(p.index())) : p;
  };
  std::unique_ptr<Record[], FreeRecords> grown(
      allocate_records(n + 1));
  Record* const to = grown.get();
  // Record is trivially copyable: its bytes move, then the ids inside follow.
  static_assert(std::is_trivially_copyable_v<Record>);
  if (at > 0) std::memcpy(static_cast<void*>(to), records_.get(), at * sizeof(Record));
  if (n > at) std::memcpy(static_cast<void*>(to + at + 1), records_.get() + at, (n - at) * sizeof(Record));
  new (to + at) Record{};
  for (std::size_t i = 0; i <= n; ++i) {
    if (i == at) continue;
    Body& b = to[i].body;
    b.next = up(b.next);
    b.prev = up(b.prev);
    Pending& p = to[i].pending;
    if (p.kind == Partner::body) p.partner = up(p.partner);
    p.last = up_partner(p.last);
    to[i].node = EventQueue::Node{};  // out of any queue: the caller sets the keys again
  }
  for (std::uint32_t& h : head) h = up(h);
  for (std::uint32_t& h : turtle_head) h = up(h);
  for (Held& h : held) {
    h.a = up_partner(h.a);
    h.b = up_partner(h.b);
  }
  if (!held.empty()) held.insert(held.begin() + at, Held{});
  records_ = std::move(grown);
  if (ball) ++nb_;
  body = {records_.get(), n + 1};
  mass = {records_.get(), nb_};
  end = {records_.get(), n + 1};
  last = {records_.get(), n + 1};
  pending = {records_.get(), n + 1};
}

}  // namespace turtlegas::sim::detail
