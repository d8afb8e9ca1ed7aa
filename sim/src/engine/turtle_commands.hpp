// SPDX-License-Identifier: MIT
// Turtles: commands, their ends, contacts, and a turtle's state.
// Part of engine.hpp (members of Engine), included at its end.
#pragma once

namespace turtlegas::sim::detail {
namespace {

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::touch(std::uint32_t id, EventKind kind, std::uint32_t other,
                                                       Vec2 normal) {
  // A turtle touched something: its command ends here (a dead stop, or a bounce that coasts to the
  // next control step), and the contact waits for its touch sensors.
  const std::size_t k = id - nb_;
  TurtleRun& r = run_[k];
  Body& b = body_[id];
  if (busy_[k] != 0) {
    busy_[k] = 0;
    r.touched = true;
    if (r.kind == TurtleCommand::Kind::turn) r.heading0 = heading_at(k, now_);
    r.amount = r.kind == TurtleCommand::Kind::move ? r.speed * (now_ - r.t_start)
               : r.kind == TurtleCommand::Kind::turn ? std::abs(r.omega) * (now_ - r.t_start)
                                                     : now_ - r.t_start;
    r.omega = 0.0;
    end_[id] = kNever;
  }
  const double vn = dot(b.v, normal);
  if (r.bounce >= 0.0 && vn < 0.0) {
    b.v = b.v - ((1.0 + r.bounce) * vn) * normal;
    // Coast until the next control step, where the program decides again.
    const double t_ext = t_base_ + now_;
    const double next_step = (std::floor(t_ext / dt_ + 1e-9) + 1.0) * dt_;
    r.coasting = true;
    end_[id] = next_step - t_base_;
  } else {
    b.v = {};
    r.coasting = false;
    end_[id] = kNever;
  }
  contacts_.push_back({t_base_ + now_, static_cast<std::uint32_t>(k), kind, other, normal});
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::end_command(std::uint32_t i) {
  // A turtle's command (or its coasting after a bounce) has run its course.
  sync(i);
  const std::size_t k = i - nb_;
  TurtleRun& r = run_[k];
  // A completed turn ends exactly where it was told to, not where omega * time rounds to.
  if (busy_[k] != 0) {
    if (r.kind == TurtleCommand::Kind::turn) r.heading0 += r.amount;
    r.amount = std::abs(r.amount);
  }
  busy_[k] = 0;
  r.coasting = false;
  r.omega = 0.0;
  end_[i] = kNever;
  if (at_rest(body_[i])) {
    // A turn or a wait: the disc stood still and stays still, so every prediction made with it
    // (its own and its neighbours') still holds. Only its key loses the command's end.
    schedule(i);
    return;
  }
  body_[i].v = {};
  after_change(i);
  last_[i] = LastPartner::none();
  repredict(i);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::command_turtle(std::size_t k, const TurtleCommand& c) {
  if (k >= run_.size()) throw std::out_of_range("command_turtle: no turtle " + std::to_string(k));
  const auto id = static_cast<std::uint32_t>(nb_ + k);
  if (body_[id].cell == kNone) return;  // it has left the arena
  sync(id);
  TurtleRun& r = run_[k];
  r.heading0 = heading_at(k, now_);
  r.kind = c.kind;
  r.coasting = false;
  r.touched = false;
  r.t_start = now_;
  r.omega = 0.0;
  r.amount = 0.0;
  Body& b = body_[id];
  const bool was_at_rest = at_rest(b);
  b.v = {};
  bool busy = false;
  switch (c.kind) {
    case TurtleCommand::Kind::stop:
      end_[id] = kNever;
      break;
    case TurtleCommand::Kind::move: {
      const double sign = c.amount >= 0.0 ? 1.0 : -1.0;
      busy = c.amount != 0.0 && r.speed > 0.0;
      end_[id] = busy ? now_ + std::abs(c.amount) / r.speed : kNever;
      if (busy) b.v = (sign * r.speed) * heading_vector(r.heading0);
      r.amount = c.amount;
      break;
    }
    case TurtleCommand::Kind::turn:
      busy = c.amount != 0.0 && r.turn_rate > 0.0;
      r.omega = busy ? (c.amount >= 0.0 ? r.turn_rate : -r.turn_rate) : 0.0;
      end_[id] = busy ? now_ + std::abs(c.amount) / r.turn_rate : kNever;
      r.amount = c.amount;
      break;
    case TurtleCommand::Kind::wait:
      busy = c.amount > 0.0;
      end_[id] = busy ? now_ + c.amount : kNever;
      r.amount = c.amount;
      break;
  }
  busy_[k] = busy ? 1 : 0;
  if (was_at_rest && at_rest(b)) {
    // A turn, a wait or a stop from rest: the disc does not move, so the predictions made with it
    // still hold (its own, kept apart from the command's end, and its neighbours'). Only its key
    // takes the command's end.
    schedule(id);
    return;
  }
  // A new course: predictions made against the old one are stale, and "just collided, cannot
  // meet again" no longer holds.
  ++b.count;
  last_[id] = LastPartner::none();
  if constexpr (kStep) dmax_ = std::max(dmax_, travel_[id] + path_length(b.v, dt_ - now_));
  repredict(id);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
TurtleState Engine<Flight, kBallBall, kStep, kExtras>::turtle(std::size_t k) const {
  const auto id = static_cast<std::uint32_t>(nb_ + k);
  const Body& b = body_[id];
  const TurtleRun& r = run_[k];
  TurtleState s;
  s.pos = b.x + (now_ - b.t) * b.v;
  s.vel = b.v;
  s.heading = heading_at(k, now_);
  s.busy = busy_[k] != 0;
  s.touched = r.touched;
  if (s.busy) {
    const double el = now_ - r.t_start;
    s.done = r.kind == TurtleCommand::Kind::move ? r.speed * el
             : r.kind == TurtleCommand::Kind::turn ? r.turn_rate * el
                                                   : el;
  } else {
    s.done = std::abs(r.amount);
  }
  return s;
}

}  // namespace
}  // namespace turtlegas::sim::detail
