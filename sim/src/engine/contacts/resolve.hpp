// SPDX-License-Identifier: MIT
// The contacts room's hook after a contact (contacts.hpp): Engine::collide serves body i's
// predicted contact (a stale one is predicted afresh), applies the response of its pair kind
// (interactions.hpp), and then, for every body of infinite-mass contact the response changed,
// asks the squeeze rule (squeeze.hpp) through squeezed(): a body caught between two obstacles of
// infinite mass is wedged (its velocity set to leave both) or crushed (removed), once per
// contact. A ball the rule holds, pushed into its holders by a ball, is answered as an obstacle
// of infinite mass (push_held). Only then are the changed bodies predicted afresh.
// (Part of the Engine, whose loop serves these events: included at engine.hpp's end.)
#pragma once

// (no #include "../engine.hpp": this file is the end of engine.hpp, read only from there)

namespace turtlegas::sim::detail {
namespace {

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::collide(std::uint32_t i) {
  const Pending p = bodies_.pending[i];
  const LastPartner before = bodies_.last[i];
  switch (p.kind) {
    case Partner::body:
      if (bodies_.body[p.partner].count != p.partner_count) {
        ++record_.stats.stale;
        sync(i);
        predict(i);
        schedule(i);
        return;
      }
      // A sliding ball that strikes or is struck is a disc again (the sliding flight).
      unslide(i);
      unslide(p.partner);
      if (is_turtle(i) || is_turtle(p.partner)) {
        // A ball is squeezed against a turtle, a turtle against a turtle; never against a ball.
        const LastPartner before_partner = bodies_.last[p.partner];
        const Changed c = apply_turtle_body(parts(), i, p.partner);
        auto before_of = [&](std::uint32_t k) { return k == i ? before : before_partner; };
        const bool keep_first = !is_turtle(c.second) || squeezed(c.first, before_of(c.first));
        const bool keep_second = squeezed(c.second, before_of(c.second));
        if (keep_first) repredict(c.first);
        if (keep_second) repredict(c.second);
      } else {
        // A ball the squeeze rule holds, pushed into its holders, is as heavy as they are.
        if (!bodies_.held.empty()) [[unlikely]] {
          const LastPartner before_partner = bodies_.last[p.partner];
          if (const std::uint32_t o = push_held(parts(), i, p.partner); o != kNone) {
            // The pusher met an obstacle of infinite mass: the squeeze rule answers it.
            const std::uint32_t k = o == i ? p.partner : i;
            if (squeezed(o, o == i ? before : before_partner)) repredict(o);
            repredict(k);
            return;
          }
        }
        served(apply_ball_ball(parts(), i, p.partner));
      }
      return;
    case Partner::wall: {
      if constexpr (kSlides) {
        unslide(i);
        if (slide_landing(i, p.partner, before)) return;
      }
      const Changed c = apply_wall(parts(), i, p.partner);
      if (squeezed(i, before) && !jammed_chain(i, p.partner, before)) served(c);
      return;
    }
    case Partner::end: {
      unslide(i);
      const Changed c = apply_end(parts(), i, p.partner);
      if (squeezed(i, before)) served(c);
      return;
    }
    case Partner::moving_end: {
      unslide(i);
      const Changed c = apply_moving_end(parts(), i, p.partner);
      if (squeezed(i, before)) served(c);
      return;
    }
    case Partner::none: break;
  }
  // A body with nothing pending has an infinite key and is never popped.
  sync(i);
  predict(i);
  schedule(i);
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
bool Engine<F, kBallBall, kStep, kExtras>::slide_landing(std::uint32_t i, std::uint32_t w, LastPartner before) {
  if constexpr (!kSlides) {
    (void)i, (void)w, (void)before;
    return false;
  } else {
    // The sliding flight (docs/physics.md): a ball pressed onto a fixed wall by a uniform field
    // (a_n < 0) that lands on it again (it met it last) at e < 1. Bouncing off it at e w, it would
    // land again after 2 e w / |a_n| at e w, then e^2 w, ...: a Zeno sequence that ends at
    // now + 2 e w / (|a_n| (1 - e)), the flight times' geometric sum. The wall and the field do
    // not change the motion along the wall, so after that the ball slides, exactly, with what it
    // has now along the wall and the field's part along it; before it, it hops at most
    // (e w)^2 / (2 |a_n|) off it. Once that is within the overlap budget, or within the rest
    // threshold's own hop |a_n| t_c^2 / 8 (it would lift the ball that high at each bounce for
    // ever, a bounce per t_c), the ball slides from now: its position differs from the exact one by
    // no more than the hop, its motion along the wall not at all, and its energy is what the whole
    // sequence leaves (the normal part, 1/2 m w^2, is what the bounces would take: restitution's,
    // not booked by a rule). Never at e = 1 (the bounces do not shrink: the sequence does not end),
    // on a moving wall, a turtle, or in a periodic arena.
    if (is_turtle(i) || !restitution_.inelastic || arena_.periodic()) return false;
    if (before != LastPartner::of(Partner::wall, w) || walls_.mover_of[w] != kNone) return false;
    sync(i);
    Body& b = bodies_.body[i];
    const Segment& s = walls_.segments[w];
    const double d = dot(arena_.rel_to_segment(b.x, s), s.n);
    const Vec2 n = d >= 0.0 ? s.n : -s.n;
    const Vec2 g = motion_.flight().a;
    const double a_n = dot(g, n);
    if (!(a_n < 0.0)) return false;
    const double w_in = std::max(-dot(b.v, n), 0.0);
    const double hop = restitution_.e * w_in;  // the next bounce's normal speed
    const double limit = std::max(std::sqrt(-2.0 * a_n * kOverlapBudget * b.r), -a_n * restitution_.tc / 2.0);
    if (!(hop <= limit)) return false;
    record_.note_contact(b.r - std::abs(d), b.r);
    const Vec2 va = b.v;
    b.v -= dot(b.v, n) * n;          // along the wall: what the sequence leaves
    b.x += (b.r - std::abs(d)) * n;  // in contact: where the sequence ends
    motion_.flight().start_slide(i, w, s, walls_.defs[w].to, n);
    Parts<F, kStep, kExtras> pa = parts();
    if (record_.impulses) [[unlikely]]
      pa.impulse(EventKind::ball_wall, i, w, bodies_.mass[i] * (b.v - va), std::abs(d) * n);
    pa.count(record_.stats.ball_wall, EventKind::ball_wall, i, w);
    ++record_.stats.slides;
    pa.changed(i);
    bodies_.last[i] = LastPartner::of(Partner::wall, w);
    repredict(i);
    return true;
  }
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
bool Engine<F, kBallBall, kStep, kExtras>::jammed_chain(std::uint32_t i, std::uint32_t w, LastPartner before) {
  // A row of balls exactly filling the room between two parallel fixed walls (docs/physics.md,
  // "Clusters: a jammed chain"). Every velocity that opens none of its contacts has no component
  // along the row (0 <= v_0 <= v_1 <= ... <= v_last <= 0 along it), and every collision's impulse
  // is along the row: the part across it is kept, and the part along it can never reach that set
  // at e = 1 (the energy along the row is kept by each collision), nor in finitely many steps at
  // e < 1. So the zero-time sequence (the impulse running down the row and back for ever) does not
  // end, and its only possible end, or limit, is the perfectly inelastic one: the row at rest
  // along itself. Asked at a contact of ball i with a fixed wall just after a ball (the impulse
  // arriving through the row): cheap unless i still touches that ball in line.
  if (is_turtle(i) || before.kind() != Partner::body || is_turtle(before.index())) return false;
  if (walls_.mover_of[w] != kNone) return false;
  const Body& bi = bodies_.body[i];
  const Segment& sw = walls_.segments[w];
  const double dw = dot(arena_.rel_to_segment(bi.x, sw), sw.n);
  const Vec2 n = dw >= 0.0 ? sw.n : -sw.n;  // from the wall along the row
  constexpr double kParallel = 1e-9;  // as the squeeze rule's parallel walls
  // The ball at `at` (radius ra) and ball k touch in line with the row, k further along it.
  auto in_line = [&](Vec2 at, double ra, std::uint32_t k) {
    const Body& bk = bodies_.body[k];
    const Vec2 rel = arena_.min_image(motion_.pos(bk, k, now_ - bk.t) - at);
    const double dist = norm(rel);
    return dot(rel, n) > 0.0 && std::abs(sim::cross(rel, n)) <= kParallel * dist &&
           touching(dist - (ra + bk.r), std::min(ra, bk.r), at);
  };
  if (!in_line(bi.x, bi.r, before.index())) return false;
  // Walk the row: each ball touches exactly one ball further along it, until one touches a fixed
  // wall facing w (parallel, on its far side). A branch, a gap or no such wall: not this rule.
  std::vector<std::uint32_t> row{i};
  std::vector<std::uint32_t> near;
  std::uint32_t far = kNone;
  for (std::uint32_t cur = i; row.size() <= bodies_.balls();) {
    const Body& bc = bodies_.body[cur];
    const Vec2 xc = motion_.pos(bc, cur, now_ - bc.t);
    const double reach = bc.r + 2.0 * step_.rmax;
    near.clear();
    balls_in_rect(xc - Vec2{reach, reach}, xc + Vec2{reach, reach}, near);
    std::uint32_t next = kNone;
    for (std::uint32_t k : near) {
      if (k == cur || is_turtle(k) || !in_line(xc, bc.r, k)) continue;
      if (next != kNone) return false;  // a branch
      next = k;
    }
    if (next != kNone) {
      row.push_back(next);
      cur = next;
      continue;
    }
    for (std::uint32_t v = 0; v < walls_.segments.size(); ++v) {
      if (v == w || walls_.mover_of[v] != kNone) continue;
      if constexpr (kExtras)
        if (!bodies_.layers[cur].collides_with(walls_.layers[v])) continue;
      const Segment& sv = walls_.segments[v];
      const Vec2 rel = arena_.rel_to_segment(xc, sv);
      const double foot = dot(rel, sv.u), d = dot(rel, sv.n);
      const Vec2 nv = d >= 0.0 ? sv.n : -sv.n;
      if (foot < 0.0 || foot > sv.len || dot(nv, n) >= 0.0 || std::abs(sim::cross(nv, n)) > kParallel) continue;
      if (touching(std::abs(d) - bc.r, bc.r, xc)) {
        far = v;
        break;
      }
    }
    break;
  }
  if (far == kNone) return false;
  // Jammed: the limit. Each ball keeps its velocity across the row; the ledger books what it had
  // along it (at e = 1 a rattle of zero amplitude would keep it: not tracked, reported instead).
  for (std::uint32_t k : row) sync(k);
  Parts<F, kStep, kExtras> pa = parts();
  for (std::uint32_t k : row) {
    Body& bk = bodies_.body[k];
    const double vn = dot(bk.v, n);
    const Vec2 v = bk.v - vn * n;
    record_.take_energy(record_.stats.energy_wedged, k, 0.5 * bodies_.mass[k] * (norm2(bk.v) - norm2(v)));
    bk.v = v;
    pa.changed(k);
    // Its contacts in the row are answered at this instant (the mark the squeeze rule leaves).
    bodies_.hold(k, LastPartner::of(Partner::wall, w), LastPartner::of(Partner::wall, far), now_, motion_.straight(k));
  }
  record_.note(t_base_ + now_, EventKind::wedged, i, w, far, 0);
  ++record_.stats.wedged;
  for (std::uint32_t k : row) repredict(k);
  return true;
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
bool Engine<F, kBallBall, kStep, kExtras>::squeezed(std::uint32_t i, LastPartner before) {
  Side A, B;
  if (squeeze(parts(), i, before, bodies_.last[i], A, B) != Squeeze::crushed) return true;
  crush(i, A, B);
  return false;
}

}  // namespace
}  // namespace turtlegas::sim::detail
