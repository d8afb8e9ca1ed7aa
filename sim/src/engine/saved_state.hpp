// SPDX-License-Identifier: MIT
// The engine's whole memory as plain data, and back (World::save_state, World::restore_state;
// turtlegas/sim/engine_state.hpp says what is kept and why). A restored engine is the one that
// saved the state: the same records bit for bit, the same cell lists in the same order, the same
// queue keys (the queue's order of service depends on keys and ids alone, event_queue.hpp, so its
// calendar is rebuilt rather than copied). Only engines without extras are saved. (Part of the
// Engine: included at engine.hpp's end.)
#pragma once

// (no #include "engine.hpp": this file is the end of engine.hpp, read only from there)

namespace turtlegas::sim::detail {
namespace {

/// The name of an engine row, as a saved state carries it.
template <class F, bool kBallBall, bool kStep, bool kExtras>
std::string variant_name() {
  return std::string(F::kName) + (kBallBall ? "/pairs" : "/no-pairs") + (kStep ? "/step" : "/exact") +
         (kExtras ? "/extras" : "");
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
EngineState Engine<F, kBallBall, kStep, kExtras>::save_state() const {
  if constexpr (kExtras) {
    throw std::logic_error("save_state: a scene with turtles, collision layers or moving walls is not saved");
  } else {
    EngineState s;
    s.variant = variant_name<F, kBallBall, kStep, kExtras>();
    s.now = now_;
    s.t_base = t_base_;
    s.events_since_rebase = events_since_rebase_;
    s.walls = walls_.defs.size();
    const std::size_t n = bodies_.size();
    s.bodies.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      const Body& b = bodies_.body[i];
      const Pending& p = bodies_.pending[i];
      EngineState::Body& o = s.bodies[i];
      o.x = b.x;
      o.v = b.v;
      o.t = b.t;
      o.count = b.count;
      o.cell = b.cell;
      o.next = b.next;
      o.prev = b.prev;
      o.t_coll = p.t_coll;
      o.t_cross = p.t_cross;
      o.partner = p.partner;
      o.partner_count = p.partner_count;
      o.last = p.last.code();
      o.kind = static_cast<std::uint8_t>(p.kind);
      o.cross_dir = p.cross_dir;
      o.queued = heap_.contains(i);
      o.key = o.queued ? heap_.key(i) : 0.0;
    }
    for (const BodyStore::Held& h : bodies_.held)
      s.held.push_back({h.a.code(), h.b.code(), h.count, h.count_a, h.count_b, h.straight, h.t});
    s.last_time = restitution_.last_time;
    if constexpr (kSlides)
      for (const Slide& sl : motion_.flight().slides())
        s.slides.push_back({sl.a, sl.s.p1, sl.s.u, sl.s.n, sl.p2, sl.s.len, sl.wall});
    s.step_index = step_.index;
    s.step_dmax = step_.dmax;
    s.step_scan = step_.scan;
    s.step_stamp = step_.stamp;
    s.step_travel = step_.travel;
    s.stats = record_.stats;
    s.max_contact = record_.max_contact;
    s.energy_taken = record_.taken;
    return s;
  }
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::restore_state(const EngineState& s) {
  if constexpr (kExtras) {
    (void)s;
    throw std::invalid_argument("restore_state: a scene with turtles, collision layers or moving walls is not restored");
  } else {
    // Every check first: a state that does not fit changes nothing.
    const std::string mine = variant_name<F, kBallBall, kStep, kExtras>();
    auto refuse = [](const std::string& why) { throw std::invalid_argument("restore_state: " + why); };
    if (s.variant != mine) refuse("the state is of engine " + s.variant + ", this world's is " + mine);
    const auto n = static_cast<std::uint32_t>(bodies_.size());
    if (s.bodies.size() != n) refuse("the state has " + std::to_string(s.bodies.size()) + " bodies, the world " + std::to_string(n));
    if (s.walls != walls_.defs.size()) refuse("the state has " + std::to_string(s.walls) + " walls, the world " + std::to_string(walls_.defs.size()));
    const auto cells = static_cast<std::uint32_t>(bodies_.head.size());
    const std::size_t segments = walls_.segments.size(), ends = walls_.ends.size();
    auto partner_ok = [&](Partner kind, std::uint32_t index) {
      switch (kind) {
        case Partner::none: return true;
        case Partner::body: return index < n;
        case Partner::wall: return index < segments;
        case Partner::end: return index < ends;
        case Partner::moving_end: return false;  // no moving walls without extras
      }
      return false;
    };
    auto last_ok = [&](std::uint32_t code) {
      const LastPartner l = LastPartner::from_code(code);
      return l.is_none() || partner_ok(l.kind(), l.index());
    };
    std::vector<std::uint32_t> head(cells, kNone);
    std::uint32_t alive = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      const EngineState::Body& b = s.bodies[i];
      const std::string who = "body " + std::to_string(i) + ": ";
      if (!std::isfinite(b.x.x) || !std::isfinite(b.x.y) || !std::isfinite(b.v.x) || !std::isfinite(b.v.y) ||
          !std::isfinite(b.t))
        refuse(who + "a position, velocity or time is not finite");
      if (b.kind > static_cast<std::uint8_t>(Partner::moving_end) || !partner_ok(static_cast<Partner>(b.kind), b.partner) ||
          !last_ok(b.last) || b.cross_dir > kSlideEnd)
        refuse(who + "its prediction names no such partner");
      if (b.cell == kNone) {
        if (b.queued) refuse(who + "gone, yet queued");
        continue;
      }
      ++alive;
      if (b.cell >= cells) refuse(who + "no such cell");
      if (b.next != kNone && (b.next >= n || s.bodies[b.next].cell != b.cell || s.bodies[b.next].prev != i))
        refuse(who + "its cell list does not hold together");
      if (b.prev == kNone) {
        if (head[b.cell] != kNone) refuse(who + "two lists for one cell");
        head[b.cell] = i;
      } else if (b.prev >= n || s.bodies[b.prev].cell != b.cell || s.bodies[b.prev].next != i) {
        refuse(who + "its cell list does not hold together");
      }
    }
    // Every live body is reached from its cell's head (no cycles, no orphans).
    std::uint32_t listed = 0;
    for (std::uint32_t c = 0; c < cells; ++c)
      for (std::uint32_t i = head[c]; i != kNone && listed <= n; i = s.bodies[i].next) ++listed;
    if (listed != alive) refuse("the cell lists do not hold every live body once");
    if (!s.held.empty() && s.held.size() != n) refuse("squeeze marks for " + std::to_string(s.held.size()) + " bodies");
    for (const EngineState::Held& h : s.held)
      if (!last_ok(h.a) || !last_ok(h.b)) refuse("a squeeze mark names no such partner");
    if (s.last_time.size() != restitution_.last_time.size()) refuse("the TC rule's clocks do not fit the world");
    if (kSlides ? s.slides.size() > bodies_.balls() : !s.slides.empty()) refuse("slides for balls the world has not");
    for (const EngineState::Slide& sl : s.slides)
      if (sl.wall != kNone && sl.wall >= segments) refuse("a slide along no such wall");
    if (s.step_stamp.size() != step_.stamp.size() || s.step_travel.size() != step_.travel.size())
      refuse("the step's bookkeeping does not fit the world");
    if (s.energy_taken.size() > n) refuse("energy taken from bodies the world has not");

    now_ = s.now;
    t_base_ = s.t_base;
    events_since_rebase_ = s.events_since_rebase;
    for (std::uint32_t i = 0; i < n; ++i) {
      const EngineState::Body& o = s.bodies[i];
      Body& b = bodies_.body[i];
      b.x = o.x;
      b.v = o.v;
      b.t = o.t;
      b.count = o.count;
      b.cell = o.cell;
      b.next = o.cell == kNone ? kNone : o.next;
      b.prev = o.cell == kNone ? kNone : o.prev;
      Pending& p = bodies_.pending[i];
      p.t_coll = o.t_coll;
      p.t_cross = o.t_cross;
      p.partner = o.partner;
      p.partner_count = o.partner_count;
      p.last = LastPartner::from_code(o.last);
      p.kind = static_cast<Partner>(o.kind);
      p.cross_dir = o.cross_dir;
    }
    bodies_.head.assign(head.begin(), head.end());
    bodies_.held.clear();
    for (const EngineState::Held& h : s.held)
      bodies_.held.push_back({LastPartner::from_code(h.a), LastPartner::from_code(h.b), h.count, h.count_a, h.count_b,
                              h.straight, h.t});
    restitution_.last_time = s.last_time;
    if constexpr (kSlides) {
      std::vector<Slide> slides;
      for (const EngineState::Slide& sl : s.slides) slides.push_back({sl.a, Segment{sl.p1, sl.u, sl.n, sl.len}, sl.p2, sl.wall});
      motion_.flight().restore_slides(std::move(slides));
    }
    step_.index = s.step_index;
    step_.dmax = s.step_dmax;
    step_.scan = s.step_scan;
    step_.stamp = s.step_stamp;
    step_.travel = s.step_travel;
    record_.stats = s.stats;
    record_.max_contact = s.max_contact;
    record_.taken = s.energy_taken;
    // The queue, over nodes out of any queue (as a run-time spawn rebuilds it, world_changes.hpp).
    for (std::uint32_t i = 0; i < n; ++i) bodies_.node_at(i) = EventQueue::Node{};
    heap_.reset(bodies_.nodes(), sizeof(Record), n);
    for (std::uint32_t i = 0; i < n; ++i)
      if (s.bodies[i].queued) heap_.set(i, s.bodies[i].key);
    arm_check();  // the event count has moved: the limit and the poll count from it
  }
}

}  // namespace
}  // namespace turtlegas::sim::detail
