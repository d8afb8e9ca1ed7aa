// SPDX-License-Identifier: MIT
// Changes to a running world: spawn a ball or a turtle, remove one, teleport one (World's
// spawn_ball ... teleport_turtle). A host calls them between calls to advance_to, at a control
// boundary.
//
// What they keep: every other body's events, exactly. Only the body concerned is predicted again.
// That is enough: a prediction is a body's earliest contact with anything in its neighbourhood,
// so the new (or moved) body's own prediction holds every contact it can have; a neighbour whose
// prediction is earlier changes course first, which bumps its counter and makes the new body's
// prediction stale (re-predicted when popped), as in any collision. Bodies that had predicted a
// contact with a removed or moved body find it stale by its counter. Nobody else is brought to
// the present (their local times, and so their round-off, are untouched), and the queue serves
// in the order of (key, id) alone, which a spawn keeps: a new ball takes id balls() and the
// turtles' ids shift up by one together (BodyStore::insert), so every pair of old ids keeps its
// order. The rebase period (exact mode) is left as it was for the same reason.
#pragma once

namespace turtlegas::sim::detail {
namespace {

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::check_clear(Vec2 pos, double r, const Layers& layers,
                                                      std::uint32_t self) const {
  using Obstacle = PlacementError::Obstacle;
  if (!schedule_.movers.empty())
    throw PlacementError("this scene has moving walls; bodies can be spawned or moved only in scenes without them");
  // Walls, as add_wall measures a body against a new one (in its image nearest the wall).
  for (std::uint32_t w = 0; w < walls_.segments.size(); ++w) {
    if constexpr (kExtras)
      if (!walls_.layers.empty() && !walls_.layers[w].collides_with(layers)) continue;
    const Segment& seg = walls_.segments[w];
    const Vec2 rel = arena_.rel_to_segment(pos, seg);
    const double foot = std::clamp(dot(rel, seg.u), 0.0, seg.len);
    const double gap = norm(rel - foot * seg.u) - r;
    if (gap < 0.0)
      throw PlacementError("it would overlap wall '" + walls_.defs[w].id + "' by " + format_number(-gap) +
                               "; place it clear of the wall",
                           Obstacle::wall, w, -gap);
  }
  // Bodies, at the present (O(N): a change to a running world is rare; the grid is not needed).
  const std::uint32_t nb = bodies_.balls();
  for (std::uint32_t j = 0; j < bodies_.size(); ++j) {
    if (j == self) continue;
    const Body& b = bodies_.body[j];
    if (b.cell == kNone) continue;
    if constexpr (kExtras)
      if (!bodies_.layers[j].collides_with(layers)) continue;
    const Vec2 d = arena_.min_image(motion_.pos(b, j, now_ - b.t) - pos);
    const double gap = norm(d) - (b.r + r);
    if (gap < 0.0) {
      const bool turtle = is_turtle(j);
      throw PlacementError(std::string("it would overlap ") + (turtle ? "turtle #" : "ball #") +
                               std::to_string(turtle ? j - nb : j) + " by " + format_number(-gap) +
                               "; place it clear of other bodies",
                           turtle ? Obstacle::turtle : Obstacle::ball, turtle ? j - nb : j, -gap);
    }
  }
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::make_room(std::uint32_t at, bool ball, const Layers& layers) {
  const auto n = static_cast<std::uint32_t>(bodies_.size());
  auto up = [at](std::uint32_t id) { return id >= at ? id + 1 : id; };
  // The queue's contents, to set again over the moved nodes with the renumbered ids.
  std::vector<std::pair<std::uint32_t, double>> queued;
  for (std::uint32_t i = 0; i < n; ++i)
    if (heap_.contains(i)) queued.emplace_back(up(i), heap_.key(i));
  bodies_.insert(at, ball);
  if constexpr (kExtras) {
    bodies_.layers.insert(bodies_.layers.begin() + at, layers);
    if (!(layers == Layers{})) bodies_.layered = true;
  }
  (void)layers;
  if (ball) motion_.add_ball();
  if (restitution_.inelastic) restitution_.last_time.insert(restitution_.last_time.begin() + at, -kNever);
  if constexpr (kStep) step_.travel.insert(step_.travel.begin() + at, 0.0);
  heap_.reset(bodies_.nodes(), sizeof(Record), n + 1);
  for (const auto& [id, key] : queued) heap_.set(id, key);
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::place(std::uint32_t i, Vec2 pos) {
  Body& b = bodies_.body[i];
  if (arena_.periodic()) {
    pos.x -= arena_.width * std::floor(pos.x / arena_.width);
    pos.y -= arena_.height * std::floor(pos.y / arena_.height);
  }
  b.x = pos;
  b.t = now_;
  link(i, static_cast<std::uint32_t>(grid_.arena_cell_of(pos)));
  if constexpr (kStep) step_.rmax = std::max(step_.rmax, b.r);
  // Its course is new: predictions made against it are stale, and it has collided with nothing.
  new_course(i);
}

/// The checks a world file's entry gets (validate()'s messages), for one ball or turtle alone.
inline void check_entry(WorldDef one, const ArenaDef& arena) {
  one.arena = arena;
  one.arena.cell.reset();
  if (auto problem = validate(one)) throw PlacementError(problem->message);
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
std::size_t Engine<F, kBallBall, kStep, kExtras>::spawn_ball(const BallDef& ball) {
  if constexpr (std::same_as<F, ChargedFlight>)
    throw PlacementError("balls cannot be spawned into a scene with charged balls under a field (their flights keep "
                         "per-ball species); spawn into scenes without effects.electric or effects.magnetic");
  if constexpr (kStep)
    if (kick_.per_ball())
      throw PlacementError("balls cannot be spawned into a step-mode scene with charged balls under a field");
  if (bodies_.size() + 1 >= kMaxObjects) throw PlacementError("the world holds the most bodies it can");
  WorldDef one;
  one.balls.push_back(ball);
  check_entry(std::move(one), arena_.def());
  if (ball.charge != 0.0)
    throw PlacementError("a spawned ball must be uncharged (the scene's flights were chosen for the charges it "
                         "started with); give it charge 0");
  check_clear(ball.pos, ball.radius, ball.layers, kNone);
  const std::uint32_t at = bodies_.balls();
  make_room(at, true, ball.layers);
  Body& b = bodies_.body[at];
  b.r = ball.radius;
  b.v = ball.vel;
  bodies_.mass[at] = ball.mass;
  place(at, ball.pos);
  return at;
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
std::size_t Engine<F, kBallBall, kStep, kExtras>::spawn_turtle(const TurtleDef& turtle) {
  if constexpr (!kExtras) {
    (void)turtle;
    throw PlacementError("this world was built without turtles (nor layers or moving walls), so its engine keeps no "
                         "turtle lists; give the world file a turtle (or layers) to spawn turtles into it");
  } else {
    if (bodies_.size() + 1 >= kMaxObjects) throw PlacementError("the world holds the most bodies it can");
    WorldDef one;
    one.turtles.push_back(turtle);
    check_entry(std::move(one), arena_.def());
    check_clear(turtle.pos, turtle.radius, turtle.layers, kNone);
    const auto at = static_cast<std::uint32_t>(bodies_.size());
    make_room(at, false, turtle.layers);
    turtles_.add(turtle);
    Body& b = bodies_.body[at];
    b.r = turtle.radius;
    b.v = {};
    bodies_.end[at] = kNever;
    turtles_.place(turtles_.size() - 1, turtle.heading, b, bodies_.end[at], now_);
    place(at, turtle.pos);
    return turtles_.size() - 1;
  }
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::remove_body(bool turtle, std::size_t k) {
  const std::size_t count = turtle ? turtles_.size() : bodies_.balls();
  if (k >= count)
    throw std::out_of_range(std::string("no ") + (turtle ? "turtle" : "ball") + " #" + std::to_string(k));
  const auto i = static_cast<std::uint32_t>(turtle ? bodies_.balls() + k : k);
  Body& b = bodies_.body[i];
  if (b.cell == kNone)
    throw std::invalid_argument(std::string(turtle ? "turtle" : "ball") + " #" + std::to_string(k) +
                                " has left the world already");
  sync(i);
  unlink(i);  // (retire()'s steps: see there why they are written out here)
  b.cell = kNone;
  ++b.count;  // predictions made against it are now stale
  heap_.remove(i);
  if constexpr (kSlides) motion_.flight().end_slide(i);
  if (turtle) turtles_.exit(k, b, bodies_.end[i]);
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::teleport_ball(std::size_t k, Vec2 pos, Vec2 vel) {
  if (k >= bodies_.balls()) throw std::out_of_range("no ball #" + std::to_string(k));
  const auto i = static_cast<std::uint32_t>(k);
  if (bodies_.body[i].cell == kNone) throw std::invalid_argument("ball #" + std::to_string(k) + " has left the world");
  BallDef d;
  d.pos = pos;
  d.vel = vel;
  d.radius = bodies_.body[i].r;
  d.mass = bodies_.mass[i];
  WorldDef one;
  one.balls.push_back(d);
  check_entry(std::move(one), arena_.def());
  Layers layers{};
  if constexpr (kExtras) layers = bodies_.layers[i];
  check_clear(pos, d.radius, layers, i);
  sync(i);
  unlink(i);
  if constexpr (kSlides) motion_.flight().end_slide(i);  // a disc again where it is put
  bodies_.body[i].v = vel;
  place(i, pos);
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::teleport_turtle(std::size_t k, Vec2 pos, double heading) {
  if constexpr (!kExtras) {
    (void)pos;
    (void)heading;
    throw std::out_of_range("no turtle #" + std::to_string(k));
  } else {
    if (k >= turtles_.size()) throw std::out_of_range("no turtle #" + std::to_string(k));
    const auto i = static_cast<std::uint32_t>(bodies_.balls() + k);
    if (bodies_.body[i].cell == kNone)
      throw std::invalid_argument("turtle #" + std::to_string(k) + " has left the world");
    TurtleDef d;
    d.pos = pos;
    d.heading = heading;
    d.radius = bodies_.body[i].r;
    WorldDef one;
    one.turtles.push_back(d);
    check_entry(std::move(one), arena_.def());
    check_clear(pos, d.radius, bodies_.layers[i], i);
    sync(i);
    unlink(i);
    turtles_.place(k, heading, bodies_.body[i], bodies_.end[i], now_);
    motion_.set_arc(k, 0.0);
    place(i, pos);
  }
}

}  // namespace
}  // namespace turtlegas::sim::detail
