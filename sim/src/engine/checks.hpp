// SPDX-License-Identifier: MIT
// Checks: energy and the overlap measure.
// Part of engine.hpp (members of Engine), included at its end.
#pragma once

#include "../overlap.hpp"

namespace turtlegas::sim::detail {
namespace {

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
double Engine<Flight, kBallBall, kStep, kExtras>::energy() const {
  const Vec2 g = kStep ? kick_ : flight_.a;
  double e = 0.0;
  for (std::size_t i = 0; i < nb_; ++i) {
    const BallState s = ball(i);
    if (!s.alive) continue;
    e += 0.5 * mass_[i] * norm2(s.vel) - mass_[i] * dot(g, s.pos);
  }
  return e;
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
Overlap Engine<Flight, kBallBall, kStep, kExtras>::measure_overlap() const {
  // Read in place: no copy of the bodies (a million of them would add ~40 bytes a ball to the peak).
  const std::size_t n = body_.size();
  auto pos = [&](std::size_t i) { return pos_at(body_[i], static_cast<std::uint32_t>(i), now_ - body_[i].t); };
  auto rad = [&](std::size_t i) { return body_[i].r; };
  auto alive = [&](std::size_t i) { return body_[i].cell != kNone; };
  const DiscView discs{n, pos, rad, alive};
  const bool periodic = boundary_ == Boundary::periodic;
  std::vector<Segment> walls_now = walls_;
  for (const Mover& m : movers_) walls_now[m.wall] = mover_segment(m, now_);
  if (!kBallBall && nb_ > 0) {
    // Balls pass through each other by request: measure walls for everyone, and pairs among the
    // turtles and between turtles and balls.
    Overlap worst = deepest_overlap(discs, walls_now, periodic ? width_ : 0.0, periodic ? height_ : 0.0, false,
                                       kExtras ? &layers_ : nullptr, kExtras ? &wall_layers_ : nullptr);
    for (std::uint32_t t = nb_; t < n; ++t) {
      if (!alive(t)) continue;
      for (std::uint32_t j = 0; j < n; ++j) {
        if (j == t || !alive(j) || (j >= nb_ && j < t) || !meets(t, j)) continue;
        const double depth = rad(t) + rad(j) - norm(min_image(pos(j) - pos(t)));
        if (depth > worst.depth) worst.depth = depth;
        if (depth / std::min(rad(t), rad(j)) > worst.relative) worst.relative = depth / std::min(rad(t), rad(j));
      }
    }
    return worst;
  }
  return deepest_overlap(discs, walls_now, periodic ? width_ : 0.0, periodic ? height_ : 0.0, true,
                            kExtras ? &layers_ : nullptr, kExtras ? &wall_layers_ : nullptr);
}


}  // namespace
}  // namespace turtlegas::sim::detail
