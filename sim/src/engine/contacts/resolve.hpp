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
        // A ball that met a standing turtle right after a ball may head a jammed row (jammed_chain),
        // whose answer predicts the row afresh.
        const std::uint32_t o = is_turtle(i) ? p.partner : i, t = o == i ? p.partner : i;
        if (!is_turtle(o) && (o == c.first ? keep_first : keep_second) && before_of(o).kind() == Partner::body &&
            jammed_chain(o, LastPartner::of(Partner::body, t), before_of(o))) {
          if (t == c.first ? keep_first : keep_second) repredict(t);
          return;
        }
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
      if (squeezed(i, before) && !(before.kind() == Partner::body && jammed_chain(i, LastPartner::of(Partner::wall, p.partner), before)))
        served(c);
      return;
    }
    case Partner::end: {
      unslide(i);
      const Changed c = apply_end(parts(), i, p.partner);
      if (squeezed(i, before) && !(before.kind() == Partner::body && jammed_chain(i, LastPartner::of(Partner::end, p.partner), before)))
        served(c);
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
bool Engine<F, kBallBall, kStep, kExtras>::jammed_chain(std::uint32_t i, LastPartner obstacle, LastPartner before) {
  // A row of balls exactly filling the room between two standing obstacles (docs/physics.md,
  // "Clusters: a jammed chain"): fixed walls, fixed wall ends, standing turtles. Take n along the
  // row. The test, which proves the zero-time sequence does not end: every contact of every ball
  // of the row is either a contact of the row (a ball or an end obstacle touching it in line with
  // n) or has its normal across n. Then every impulse of the sequence is either along n (the
  // row's) or across it, so the velocities along n evolve as in a one-dimensional row between
  // two walls, where the only velocities that open none of its contacts have 0 <= v_0 . n <=
  // v_1 . n <= ... <= v_last . n <= 0, none along the row at all. At e = 1 the row's energy along
  // n is kept by each collision and is not zero (ball i approached the obstacle), so that set is
  // never reached; at e < 1 it is reached only in the limit. The limit is that set's one member:
  // every ball keeps its velocity across n and loses the one along it. A contact at any other
  // angle could take part of the impulse away (the sequence may end): the rule acts only when it
  // is proven out of the row's reach (below).
  // Asked at ball i's contact with `obstacle` right after ball `before` (the impulse arriving
  // through a row): cheap unless `before` still touches i in line.
  if constexpr (!kBallBall) {
    (void)i, (void)obstacle, (void)before;
    return false;
  } else {
    if (is_turtle(i) || before.kind() != Partner::body || is_turtle(before.index())) return false;
    const std::uint32_t nb = bodies_.balls();
    constexpr double kParallel = 1e-9;  // as the squeeze rule's parallel walls
    Parts<F, kStep, kExtras> pa = parts();
    const Look<F, kExtras> lk = look();
    // An obstacle touching a ball of the row: its normal towards the ball, and whether it stands
    // along that normal (a fixed wall or end; a turtle neither carried nor receding: one driving
    // onto the ball stops at the contact).
    struct Touch {
      LastPartner who;
      Vec2 n;
      bool standing = false;
      double gap = 0.0;  ///< the distance between their surfaces (within the contact tolerance)
    };
    auto turtle_touch = [&](std::uint32_t t, Vec2 x, double r, Touch& out) {
      const Body& bt = bodies_.body[t];
      if (bt.cell == kNone) return false;
      const Vec2 d = arena_.min_image(x - (bt.x + (now_ - bt.t) * bt.v));
      const double dist = norm(d);
      if (!(dist > 0.0) || !touching(dist - r - bt.r, std::min(r, bt.r), x)) return false;
      Vec2 vc;
      const bool arcs = motion_.any_arcs() && motion_.arcs(t);
      out = {LastPartner::of(Partner::body, t), d / dist, !arcs && !carried(pa, t, vc) && dot(bt.v, d) >= 0.0,
             dist - r - bt.r};
      return true;
    };
    // Every obstacle touching the ball of radius r at x, through `f(Touch)`.
    auto each_obstacle = [&](std::uint32_t k, Vec2 x, double r, auto&& f) {
      const std::uint32_t walls = static_cast<std::uint32_t>(walls_.segments.size());
      for (std::uint32_t v = 0; v < walls; ++v) {
        if (!lk.meets_wall(k, v)) continue;
        const std::uint32_t mi = walls_.mover_of[v];
        const Segment seg = mi == kNone ? walls_.segments[v] : schedule_.movers[mi].segment_at(walls_.segments[v], now_);
        const Vec2 rel = arena_.rel_to_segment(x, seg);
        const double foot = dot(rel, seg.u);
        const bool interior = foot > 0.0 && foot < seg.len;
        if (mi == kNone && !interior) continue;  // a fixed wall's ends are the ends' (below)
        const Vec2 off = rel - std::clamp(foot, 0.0, seg.len) * seg.u;
        const double dist = norm(off);
        if (!(dist > 0.0) || !touching(dist - r, r, x)) continue;
        const Vec2 nc = interior ? (dot(rel, seg.n) >= 0.0 ? seg.n : -seg.n) : off / dist;
        f(Touch{LastPartner::of(Partner::wall, v), nc, mi == kNone, dist - r});
      }
      const std::uint32_t ends = static_cast<std::uint32_t>(walls_.ends.size());
      for (std::uint32_t e = 0; e < ends; ++e) {
        if (!lk.meets_end(k, e)) continue;
        const Vec2 d = arena_.min_image(x - walls_.ends[e].p);
        const double dist = norm(d);
        if (!(dist > 0.0) || !touching(dist - r, r, x)) continue;
        f(Touch{LastPartner::of(Partner::end, e), d / dist, true, dist - r});
      }
      const std::uint32_t all = static_cast<std::uint32_t>(bodies_.body.size());
      for (std::uint32_t t = nb; t < all; ++t)
        if (Touch o; lk.meets(k, t) && turtle_touch(t, x, r, o)) f(o);
    };
    // The near end: the obstacle just met, standing along its normal n.
    const Body& bi = bodies_.body[i];
    Vec2 n;
    switch (obstacle.kind()) {
      case Partner::wall: {
        const std::uint32_t w = obstacle.index();
        if (walls_.mover_of[w] != kNone) return false;
        const Segment& sw = walls_.segments[w];
        const double dw = dot(arena_.rel_to_segment(bi.x, sw), sw.n);
        n = dw >= 0.0 ? sw.n : -sw.n;  // from the wall along the row
        break;
      }
      case Partner::end: {
        const Vec2 d = arena_.min_image(bi.x - walls_.ends[obstacle.index()].p);
        const double dist = norm(d);
        if (!(dist > 0.0)) return false;
        n = d / dist;
        break;
      }
      case Partner::body: {
        Touch o;
        if (!is_turtle(obstacle.index()) || !turtle_touch(obstacle.index(), bi.x, bi.r, o) || !o.standing) return false;
        n = o.n;
        break;
      }
      default: return false;
    }
    // Ball k touches the ball at `at` (radius ra); `ahead` says on which side along n, `in_line`
    // whether in line with n.
    auto ball_touch = [&](Vec2 at, double ra, std::uint32_t k, bool& ahead, bool& in_line) {
      const Body& bk = bodies_.body[k];
      const Vec2 rel = arena_.min_image(motion_.pos(bk, k, now_ - bk.t) - at);
      const double dist = norm(rel);
      if (!touching(dist - (ra + bk.r), std::min(ra, bk.r), at)) return false;
      ahead = dot(rel, n) > 0.0;
      in_line = std::abs(sim::cross(rel, n)) <= kParallel * dist;
      // (Across: |rel . n| <= kParallel dist, the caller's test.)
      return true;
    };
    {
      bool ahead = false, in_line = false;
      if (!ball_touch(bi.x, bi.r, before.index(), ahead, in_line) || !ahead || !in_line) return false;
    }
    // Walk the row from i along n: each ball's touches are classified (the test above).
    std::vector<std::uint32_t> row{i};
    std::vector<std::uint32_t> near;
    // A contact of a row ball `ball` at an angle to the row, with a ball `other` (kNone: a fixed
    // wall or end), m the unit normal from `ball` towards it, `gap` between their surfaces.
    struct Oblique {
      std::uint32_t ball, other;
      Vec2 m;
      double gap;
    };
    std::vector<Oblique> oblique;
    Touch far{};
    bool found = false;
    while (!found) {
      if (row.size() > nb) return false;  // (a ring: a periodic row)
      const std::uint32_t cur = row.back();
      const Body& bc = bodies_.body[cur];
      const Vec2 xc = motion_.pos(bc, cur, now_ - bc.t);
      const double reach = bc.r + 2.0 * step_.rmax;
      near.clear();
      balls_in_rect(xc - Vec2{reach, reach}, xc + Vec2{reach, reach}, near);
      std::uint32_t next = kNone;
      for (const std::uint32_t k : near) {
        if (k == cur || is_turtle(k) || !lk.meets(cur, k)) continue;
        bool ahead = false, in_line = false;
        if (!ball_touch(xc, bc.r, k, ahead, in_line)) continue;
        if (in_line) {
          if (!ahead) {
            if (row.size() >= 2 && k == row[row.size() - 2]) continue;
            return false;  // a ball behind the first ball, or a second one behind this one
          }
          if (next != kNone) return false;
          next = k;
          continue;
        }
        const Body& bk = bodies_.body[k];
        const Vec2 rel = arena_.min_image(motion_.pos(bk, k, now_ - bk.t) - xc);
        const double dist = norm(rel);
        if (std::abs(dot(rel, n)) > kParallel * dist) oblique.push_back({cur, k, rel / dist, dist - bc.r - bk.r});
      }
      bool ok = true;
      Touch ahead_obstacle{};
      bool has_ahead = false;
      each_obstacle(cur, xc, bc.r, [&](const Touch& o) {
        if (std::abs(sim::cross(o.n, n)) <= kParallel) {
          // In line: behind the first ball (the near end, standing) or ahead of this one (the far
          // end, standing). Anything else in line (a moving wall) is not this rule.
          if (!o.standing) ok = false;
          else if (dot(o.n, n) > 0.0) {
            if (row.size() != 1) ok = false;  // (behind the first ball: the near end)
          } else {
            ahead_obstacle = o;
            has_ahead = true;
          }
        } else if (std::abs(dot(o.n, n)) > kParallel) {
          // An obstacle at an angle: a fixed wall or end is asked below whether the row can reach
          // it; anything else (a turtle, a moving wall) could turn the impulse.
          if (o.standing && o.who.kind() != Partner::body) oblique.push_back({cur, kNone, -o.n, o.gap});
          else ok = false;
        }
      });
      if (!ok || (has_ahead && next != kNone)) return false;
      if (next != kNone) {
        row.push_back(next);
        continue;
      }
      if (!has_ahead) return false;  // the row's far end is free: the sequence ends
      far = ahead_obstacle;
      found = true;
    }
    for (const std::uint32_t k : row) sync(k);
    // Contacts at an angle to the row: the rule acts only if the row's own sequence can never close
    // one (docs/physics.md, "Clusters: a jammed chain"). One with a gap > 0 cannot: the sequence
    // takes no time and the speeds in it are bounded (below), so it is over before the gap is
    // crossed (the row is answered first, then that contact, as the engine would serve them).
    // For one in contact (gap <= 0): in the row's sequence every impulse is along n,
    // so each row ball keeps its velocity w across n, the row's energy along n, K, never grows (its
    // collisions are with each other and the standing ends, e <= 1), and |v . n| <= sqrt(2 K / m)
    // for every ball of mass m in it; the other side of the contact keeps its velocity (a fixed
    // obstacle, or a ball none of whose contacts with the row close). The contact's separating
    // speed (v_other - v_ball) . m is then at least (v_other - w) . m - |n . m| sqrt(2 K / m_ball):
    // positive, it stays open for the whole sequence, which is then the row's alone, with the
    // limit below. Otherwise the sequence runs contact by contact, and this test is asked again at
    // the row's next arrival (each impulse the oblique body takes opens it further).
    bool open_for_ever = true;
    if (!oblique.empty()) {
      double K = 0.0;
      for (const std::uint32_t k : row) {
        const double a = dot(bodies_.body[k].v, n);
        K += 0.5 * bodies_.mass[k] * a * a;
      }
      for (const Oblique& o : oblique) {
        if (o.gap > 0.0) continue;
        const Vec2 v = bodies_.body[o.ball].v, w = v - dot(v, n) * n;
        Vec2 vo{};
        if (o.other != kNone) {
          const Body& bo = bodies_.body[o.other];
          vo = motion_.vel(bo, o.other, now_ - bo.t);
        }
        const double open = dot(vo - w, o.m);
        const double reach = std::abs(dot(n, o.m)) * std::sqrt(2.0 * K / bodies_.mass[o.ball]);
        // (A margin of 1e-9 of the speeds for the round-off of the row's own collisions.)
        if (!(open - reach > 1e-9 * (norm(vo - w) + reach))) open_for_ever = false;
      }
    }
    if (!open_for_ever) {
      // The bound cannot clear a contact at an angle, but the sequence the engine serves may still
      // never close it (at e = 1 an impulse can pass a ball on before the ball's contact at the
      // angle comes up: the queue serves equal times in the order of the bodies' ids). When the
      // row and the bodies touching it at an angle come back, bit for bit, to velocities and last
      // partners they had earlier at this instant, with no time passed, the engine (whose order
      // depends on nothing else) would repeat that stretch for ever: the contacts at an angle took
      // no impulse in it that they will not take again, and the row's limit is the sequence's.
      // Otherwise the sequence runs on, and this is asked again at the row's next arrival.
      std::vector<std::uint64_t> state;
      std::vector<std::uint32_t> who(row);
      for (const Oblique& o : oblique)
        if (o.other != kNone && o.gap <= 0.0) who.push_back(o.other);
      std::sort(who.begin(), who.end());
      who.erase(std::unique(who.begin(), who.end()), who.end());
      for (const std::uint32_t k : who) {
        const Body& bk = bodies_.body[k];
        const Vec2 v = motion_.vel(bk, k, now_ - bk.t);
        state.insert(state.end(), {k, std::bit_cast<std::uint64_t>(v.x), std::bit_cast<std::uint64_t>(v.y),
                                   bodies_.last[k].code()});
      }
      if (rows_seen_.t != now_ || rows_seen_.states.empty()) rows_seen_ = {now_, {}};
      const bool again = std::find(rows_seen_.states.begin(), rows_seen_.states.end(), state) != rows_seen_.states.end();
      if (!again) {
        if (rows_seen_.states.size() < 64) rows_seen_.states.push_back(std::move(state));
        return false;
      }
    }
    rows_seen_.states.clear();
    // Jammed: the limit. Each ball keeps its velocity across the row; the ledger books what it had
    // along it (at e = 1 a rattle of zero amplitude would keep it: not tracked, reported instead).
    for (const std::uint32_t k : row) {
      Body& bk = bodies_.body[k];
      const double vn = dot(bk.v, n);
      const Vec2 v = bk.v - vn * n;
      record_.take_energy(record_.stats.energy_wedged, k, 0.5 * bodies_.mass[k] * (norm2(bk.v) - norm2(v)));
      bk.v = v;
      pa.changed(k);
      // Its contacts with the two ends are answered at this instant (the mark the squeeze rule
      // leaves).
      bodies_.hold(k, obstacle, far.who, now_, motion_.straight(k));
    }
    // The event names the ball and the two ends (a turtle by its index, an end by its wall).
    auto name = [&](LastPartner o) {
      return o.kind() == Partner::body ? o.index() - nb : o.kind() == Partner::end ? walls_.ends[o.index()].wall : o.index();
    };
    const std::uint8_t flags = static_cast<std::uint8_t>((obstacle.kind() == Partner::body ? kTurtleB : 0) |
                                                         (far.who.kind() == Partner::body ? kTurtleC : 0));
    record_.note(t_base_ + now_, EventKind::wedged, i, name(obstacle), name(far.who), flags);
    ++record_.stats.wedged;
    for (const std::uint32_t k : row) repredict(k);
    return true;
  }
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
