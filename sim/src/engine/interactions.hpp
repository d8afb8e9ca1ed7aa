// SPDX-License-Identifier: MIT
// Interactions, per pair kind: predict (consider_*), apply (collide_*), and the contact depth each records.
// Part of engine.hpp (members of Engine), included at its end.
#pragma once

namespace turtlegas::sim::detail {
namespace {

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
inline void Engine<Flight, kBallBall, kStep, kExtras>::consider_ball(std::uint32_t i, const Body& bi, std::uint32_t j,
                                                               Vec2 shift, Pending& p) const {
  // i is a ball here, j a ball.
  if (j == i || !meets(i, j)) return;
  const Body& bj = body_[j];
  const double dtj = now_ - bj.t;
  // Under uniform gravity both balls fall alike, so their relative motion is a straight line.
  const Vec2 r = flight_.pos(bj.x, bj.v, dtj) + shift - bi.x;
  const Vec2 v = flight_.vel(bj.v, dtj) - bi.v;
  const double t = now_ + toi_disc_disc(r, v, bi.r + bj.r);
  if (t < p.t_coll) {
    // Checked only for a winner: most candidates miss, and last_[j] is a cache miss.
    if (last_[i] == LastPartner::of(Partner::body, j) && last_[j] == LastPartner::of(Partner::body, i)) return;
    p.take(t, Partner::body, j, bj.count);
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::consider_turtle(std::uint32_t i, const Body& bi, std::uint32_t j,
                                                                 Vec2 shift, Pending& p) const {
  // j is a turtle (straight flight); i a ball or a turtle.
  if (j == i || !meets(i, j)) return;
  const Body& bj = body_[j];
  const Vec2 rel = bi.x - (bj.x + (now_ - bj.t) * bj.v + shift);
  const Vec2 v = bi.v - bj.v;
  double dt;
  if (Flight::kAccelerates && !is_turtle(i)) dt = toi_disc_point_accel(rel, v, flight_.a, bi.r + bj.r, p.t_coll - now_);
  else dt = toi_disc_disc(rel, v, bi.r + bj.r);
  const double t = now_ + dt;
  if (t < p.t_coll) {
    if (straight(i) && last_[i] == LastPartner::of(Partner::body, j) && last_[j] == LastPartner::of(Partner::body, i)) return;
    p.take(t, Partner::body, j, bj.count);
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::consider_wall(std::uint32_t i, const Body& bi, std::uint32_t w,
                                                               Vec2 shift, Pending& p) const {
  if (!meets_wall(i, w) || (straight(i) && last_[i] == LastPartner::of(Partner::wall, w))) return;
  const Segment& s = walls_[w];
  // Relative to the wall's first end, so walls far from the origin lose nothing.
  const double t = now_ + toi_disc_segment(bi.x - (s.p1 + shift), bi.v, accel(i), s, bi.r);
  if (t < p.t_coll) {
    p.take(t, Partner::wall, w);
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::consider_end(std::uint32_t i, const Body& bi, std::uint32_t e,
                                                              Vec2 shift, Pending& p) const {
  if (!meets_end(i, e) || (straight(i) && last_[i] == LastPartner::of(Partner::end, e))) return;
  const Vec2 rel = bi.x - (ends_[e].p + shift);
  double dt;
  if (Flight::kAccelerates && !is_turtle(i)) dt = toi_disc_point_accel(rel, bi.v, flight_.a, bi.r, p.t_coll - now_);
  else dt = toi_disc_point(rel, bi.v, bi.r);
  const double t = now_ + dt;
  if (t < p.t_coll) {
    p.take(t, Partner::end, e);
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::consider_ball_from_turtle(std::uint32_t i, const Body& bi,
                                                                           std::uint32_t j, Vec2 shift,
                                                                           Pending& p) const {
  // i is a turtle (straight flight), j a ball (which may fall).
  if (!meets(i, j)) return;
  const Body& bj = body_[j];
  const double dtj = now_ - bj.t;
  const Vec2 rel = flight_.pos(bj.x, bj.v, dtj) + shift - bi.x;
  const Vec2 v = flight_.vel(bj.v, dtj) - bi.v;
  double dt;
  if constexpr (Flight::kAccelerates) dt = toi_disc_point_accel(rel, v, flight_.a, bi.r + bj.r, p.t_coll - now_);
  else dt = toi_disc_disc(rel, v, bi.r + bj.r);
  const double t = now_ + dt;
  if (t < p.t_coll) {
    if (!Flight::kAccelerates && last_[i] == LastPartner::of(Partner::body, j) && last_[j] == LastPartner::of(Partner::body, i)) return;
    p.take(t, Partner::body, j, bj.count);
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::collide(std::uint32_t i) {
  const Pending p = pending_[i];
  switch (p.kind) {
    case Partner::body:
      if (body_[p.partner].count != p.partner_count) {
        ++stats_.stale;
        sync(i);
        predict(i);
        schedule(i);
        return;
      }
      if (is_turtle(i) || is_turtle(p.partner)) collide_with_turtle(i, p.partner);
      else collide_balls(i, p.partner);
      return;
    case Partner::wall: collide_wall(i, p.partner); return;
    case Partner::end: collide_end(i, p.partner); return;
    case Partner::moving_end: collide_moving_end(i, p.partner); return;
    case Partner::none: break;
  }
  // A body with nothing pending has an infinite key and is never popped.
  sync(i);
  predict(i);
  schedule(i);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
double Engine<Flight, kBallBall, kStep, kExtras>::restitution_for(std::uint32_t i) const {
  // The TC rule (Luding & McNamara): a ball that collided less than tc ago collides elastically,
  // so a cluster cannot collapse into infinitely many collisions in finite time.
  return now_ - last_time_[i] < tc_ ? 1.0 : e_;
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
Vec2 Engine<Flight, kBallBall, kStep, kExtras>::bounce(std::uint32_t i, Vec2 v, Vec2 n) const {
  // n: unit contact normal pointing from the obstacle to the ball; v relative to the obstacle.
  // Walls take the plain restitution: the TC rule is for ball clusters; a ball pressed onto a wall
  // is kept from collapsing by the rest threshold below.
  const double w = -dot(v, n);
  double w_out = e_ * w;
  if constexpr (Flight::kAccelerates) {
    // The rest threshold: a ball pressed onto the obstacle by the field leaves it at least fast
    // enough to stay away for tc. Without it an inelastic ball would bounce infinitely often before
    // coming to rest, and a ball at rest would sink.
    const double a_n = dot(accel(i), n);
    if (a_n < 0.0) w_out = std::max(w_out, -a_n * tc_ / 2.0);
  }
  return v + (w + w_out) * n;
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::collide_balls(std::uint32_t i, std::uint32_t j) {
  sync(i);
  sync(j);
  Body& a = body_[i];
  Body& b = body_[j];
  const Vec2 F = min_image(b.x - a.x);
  const double sigma = a.r + b.r;
  note_contact(sigma - norm(F), std::min(a.r, b.r));
  double e = e_;
  if (inelastic_) e = std::max(restitution_for(i), restitution_for(j));
  respond_disc_disc(a.v, b.v, mass_[i], mass_[j], F, e);
  ++stats_.ball_ball;
  log(EventKind::ball_ball, i, j);
  after_change(i);
  after_change(j);
  last_[i] = LastPartner::of(Partner::body, j);
  last_[j] = LastPartner::of(Partner::body, i);
  repredict(i);
  repredict(j);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::collide_with_turtle(std::uint32_t i, std::uint32_t j) {
  sync(i);
  sync(j);
  // Name the pair (turtle, other) with the turtle first.
  const std::uint32_t t = is_turtle(i) ? i : j;
  const std::uint32_t o = t == i ? j : i;
  Body& bt = body_[t];
  Body& bo = body_[o];
  const Vec2 F = min_image(bo.x - bt.x);  // from the turtle to the other body
  const double dist = norm(F);
  note_contact(bt.r + bo.r - dist, std::min(bt.r, bo.r));
  const Vec2 n = F / dist;
  if (!is_turtle(o)) {
    // The turtle stops dead (or bounces) at the contact first; the ball then bounces off it as
    // off a wall of infinite mass moving at the turtle's new velocity. (Against the old velocity,
    // a ball that caught up with a turtle from behind would keep closing on it once it stopped.)
    touch(t, EventKind::turtle_ball, o, -n);
    const Vec2 w = bo.v - bt.v;
    if (dot(w, n) < 0.0) bo.v = bt.v + bounce(o, w, n);
    ++stats_.turtle_ball;
    log(EventKind::turtle_ball, t - nb_, o);
  } else {
    ++stats_.turtle_turtle;
    log(EventKind::turtle_turtle, t - nb_, o - nb_);
    touch(t, EventKind::turtle_turtle, o - nb_, -n);
    touch(o, EventKind::turtle_turtle, t - nb_, n);
  }
  after_change(t);
  after_change(o);
  last_[t] = LastPartner::of(Partner::body, o);
  last_[o] = LastPartner::of(Partner::body, t);
  repredict(t);
  repredict(o);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::collide_wall(std::uint32_t i, std::uint32_t w) {
  sync(i);
  Body& a = body_[i];
  const std::uint32_t mi = mover_of_[w];
  const Segment s = mi == kNone ? walls_[w] : mover_segment(movers_[mi], now_);
  // The velocity of the wall's material point at the contact: the ends' velocities interpolated
  // at the foot (the same for every point of a translating wall).
  Vec2 u{};
  if (mi != kNone) {
    const Mover& m = movers_[mi];
    u = m.u;
    if (!m.rigid()) u += std::clamp(dot(a.x - s.p1, s.u) / s.len, 0.0, 1.0) * m.w;
  }
  const double d = dot(rel_to_segment(a.x, s), s.n);
  const Vec2 n = d >= 0.0 ? s.n : -s.n;
  note_contact(a.r - std::abs(d), a.r);
  if (is_turtle(i)) {
    ++stats_.turtle_wall;
    log(EventKind::turtle_wall, i - nb_, w);
    touch(i, EventKind::turtle_wall, w, n);
    if (dot(u, n) > 0.0) {
      // A moving wall pushing a turtle carries it along at its normal speed (both have
      // infinite mass), until the wall's next keyframe. A turning or stretching wall's push
      // changes along the way, so it knocks the turtle off instead, at twice its normal speed
      // (an elastic bounce off the wall), which the wall can only catch up with by speeding up.
      a.v = (movers_[mi].rigid() ? 1.0 : 2.0) * dot(u, n) * n;
      pushed_by_[i - nb_] = mi;
    }
  } else {
    a.v = u + bounce(i, a.v - u, n);
    ++stats_.ball_wall;
    log(EventKind::ball_wall, i, w);
  }
  after_change(i);
  last_[i] = LastPartner::of(Partner::wall, w);
  repredict(i);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::collide_end(std::uint32_t i, std::uint32_t e) {
  sync(i);
  Body& a = body_[i];
  const Vec2 F = min_image(a.x - ends_[e].p);
  const double dist = norm(F);
  note_contact(a.r - dist, a.r);
  if (is_turtle(i)) {
    ++stats_.turtle_wall_end;
    log(EventKind::turtle_wall_end, i - nb_, ends_[e].wall);
    touch(i, EventKind::turtle_wall_end, ends_[e].wall, F / dist);
  } else {
    a.v = bounce(i, a.v, F / dist);
    ++stats_.ball_wall_end;
    log(EventKind::ball_wall_end, i, ends_[e].wall);
  }
  after_change(i);
  last_[i] = LastPartner::of(Partner::end, e);
  repredict(i);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::consider_mover(std::uint32_t i, const Body& bi, std::uint32_t mi,
                                                               Pending& p) const {
  // In the wall's frame the body flies with v - u; contacts after the next keyframe are not
  // predicted (the keyframe makes everyone predict again).
  const Mover& m = movers_[mi];
  const std::uint32_t w = m.wall;
  if (!meets_wall(i, w)) return;
  const Segment& s = walls_[w];
  const Vec2 p1 = mover_p1(m, now_);
  const Vec2 v = bi.v - m.u;
  const double horizon = std::min(p.t_coll, next_key_);
  double t_wall = kNever;
  if (!m.rigid()) {
    // Turning or stretching: no straight-line argument rules out meeting the same wall again.
    t_wall = now_ + toi_disc_deforming_segment(bi.x - p1, v, accel(i), mover_d(m, now_), m.w, bi.r, horizon - now_);
  } else if (!(straight(i) && last_[i] == LastPartner::of(Partner::wall, w))) {
    t_wall = now_ + toi_disc_segment(bi.x - p1, v, accel(i), s, bi.r);
  }
  if (t_wall < p.t_coll && t_wall <= horizon) {
    p.take(t_wall, Partner::wall, w);
  }
  for (std::uint32_t which = 0; which < 2; ++which) {
    const std::uint32_t code = 2 * mi + which;
    if (straight(i) && last_[i] == LastPartner::of(Partner::moving_end, code)) continue;
    // Each end moves in a straight line, so its contacts have the closed forms of a fixed point.
    const Vec2 e = mover_end(m, which == 1, now_);
    const Vec2 ve = which == 0 ? v : v - m.w;  // the body's velocity relative to that end
    double dt;
    if (Flight::kAccelerates && !is_turtle(i)) dt = toi_disc_point_accel(bi.x - e, ve, flight_.a, bi.r, horizon - now_);
    else dt = toi_disc_point(bi.x - e, ve, bi.r);
    const double t = now_ + dt;
    if (t < p.t_coll && t <= horizon) {
      p.take(t, Partner::moving_end, code);
    }
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::collide_moving_end(std::uint32_t i, std::uint32_t code) {
  sync(i);
  Body& a = body_[i];
  const Mover& m = movers_[code / 2];
  const bool second = code % 2 == 1;
  const Vec2 e = mover_end(m, second, now_);
  const Vec2 ue = mover_end_velocity(m, second);
  const Vec2 F = a.x - e;
  const double dist = norm(F);
  note_contact(a.r - dist, a.r);
  if (is_turtle(i)) {
    ++stats_.turtle_wall_end;
    log(EventKind::turtle_wall_end, i - nb_, m.wall);
    touch(i, EventKind::turtle_wall_end, m.wall, F / dist);
  } else {
    a.v = ue + bounce(i, a.v - ue, F / dist);
    ++stats_.ball_wall_end;
    log(EventKind::ball_wall_end, i, m.wall);
  }
  after_change(i);
  last_[i] = LastPartner::of(Partner::moving_end, code);
  repredict(i);
}

}  // namespace
}  // namespace turtlegas::sim::detail
