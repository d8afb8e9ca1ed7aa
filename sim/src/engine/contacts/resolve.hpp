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
      const Changed c = apply_wall(parts(), i, p.partner);
      if (squeezed(i, before)) served(c);
      return;
    }
    case Partner::end: {
      const Changed c = apply_end(parts(), i, p.partner);
      if (squeezed(i, before)) served(c);
      return;
    }
    case Partner::moving_end: {
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
bool Engine<F, kBallBall, kStep, kExtras>::squeezed(std::uint32_t i, LastPartner before) {
  Side A, B;
  if (squeeze(parts(), i, before, bodies_.last[i], A, B) != Squeeze::crushed) return true;
  crush(i, A, B);
  return false;
}

}  // namespace
}  // namespace turtlegas::sim::detail
