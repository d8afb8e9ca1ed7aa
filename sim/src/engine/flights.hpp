// SPDX-License-Identifier: MIT
// Flights: how a ball moves between events under the scene's field, and the times of impact that
// motion implies. A flight owns every choice that depends on the motion: where a ball is, when it
// leaves its cell, which time-of-impact function meets it with another ball, a point, a segment or
// a deforming segment, whether a pair that has just collided may be skipped, the field's pull
// along a normal (the rest threshold) and its potential (the energy).
//
// Turtles never use a flight: they drive on the floor and always fly straight (Motion, below).
// Step mode never uses one either: it flies straight and kicks between steps (kick.hpp).
//
// Adding a flight: one struct that satisfies `Flight`, the pure functions it calls (toi.hpp, each
// tested against brute force), and its rows in the table of variants (factory.cpp). A flight that
// needs something per ball (a charge-to-mass ratio, a species index) keeps it itself, built from
// the scene in its constructor, and reads it by the ball's index: Record stays 128 bytes for the
// scenes that do not use it. docs/architecture.md works through an example.
#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <string_view>
#include <vector>

#include "contacts/contacts.hpp"
#include "records.hpp"
#include "turtlegas/sim/field_toi.hpp"
#include "turtlegas/sim/toi.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::sim::detail {

/// Whether some charged ball feels an electric or magnetic field: then only ChargedFlight (exact
/// mode) or a Kick with species (step mode) flies the scene right.
bool charges_feel_fields(const WorldDef& def);

/// The cell a body is in, as the times it would leave it are measured against.
struct CellBox {
  double x_lo, x_hi, y_lo, y_hi;
};

/// When a body leaves its cell, and through which side: 0 -x, 1 +x, 2 -y, 3 +y.
struct CellExit {
  double t = kNever;
  std::uint8_t dir = 0;
};

/// The earlier of two axis exits (x first at a tie).
inline CellExit earlier_exit(AxisExit ex, AxisExit ey) {
  if (ex.t <= ey.t) return {ex.t, static_cast<std::uint8_t>(ex.upper ? 1 : 0)};
  return {ey.t, static_cast<std::uint8_t>(ey.upper ? 3 : 2)};
}

/// A straight line's exit from [lo, hi] along one axis.
inline AxisExit straight_exit(double x, double v, double lo, double hi) {
  if (v > 0.0) return {std::max(0.0, (hi - x) / v), true};
  if (v < 0.0) return {std::max(0.0, (lo - x) / v), false};
  return {};
}

/// What every flight provides. `ball` is a ball's index (flights that need per-ball parameters
/// read them by it); times of impact are relative to now, kNever for none, and need not look past
/// `t_max` (the prediction's horizon: the earliest candidate so far).
template <class F>
concept Flight = std::constructible_from<F, const WorldDef&> &&
    requires(const F f, const WorldDef& def, std::uint32_t ball, std::uint32_t other, Vec2 x, Vec2 v, double dt,
             double sigma, double t_max, const Segment& s, Vec2 d0, Vec2 w, const CellBox& box) {
  { F::kName } -> std::convertible_to<std::string_view>;
  /// Whether this flight is exact for the scene (its effects, and the balls' own parameters: a
  /// charged flight is not needed when no ball is charged). The factory takes the first row of its
  /// table whose flight fits.
  { F::fits(def) } -> std::same_as<bool>;
  /// Where the ball is, and how fast it goes, dt after being at x with velocity v.
  { f.pos(ball, x, v, dt) } -> std::same_as<Vec2>;
  { f.vel(ball, v, dt) } -> std::same_as<Vec2>;
  /// When the ball, at x with velocity v, leaves the cell `box`.
  { f.cell_exit(ball, x, v, box) } -> std::same_as<CellExit>;
  /// Two balls, `other` at x relative to `ball`, flying at v (ball) and w (other): when their
  /// distance falls to sigma.
  { f.toi_balls(ball, other, x, v, w, sigma, t_max) } -> std::same_as<double>;
  /// The ball at x relative to a point that flies straight at w, v relative to it: when their
  /// distance falls to sigma (a wall end, a moving wall's end, a turtle's centre). (Under a
  /// magnetic field the point's own velocity matters: it is a field in the point's frame.)
  { f.toi_point(ball, x, v, w, sigma, t_max) } -> std::same_as<double>;
  /// The ball at x relative to segment s's first end, v relative to the segment, which translates
  /// at w: when it touches the segment's interior.
  { f.toi_segment(ball, x, v, w, s, sigma, t_max) } -> std::same_as<double>;
  /// The same for a segment whose ends move apart (d0 + w t from its first end).
  { f.toi_deforming_segment(ball, x, v, d0, w, sigma, t_max) } -> std::same_as<double>;
  /// Whether the ball flies straight, and so whether its motion relative to something that flies
  /// straight is a straight line: then a pair that has just collided cannot meet again before
  /// either changes course, and the prediction skips it (LastPartner).
  { f.straight(ball) } -> std::same_as<bool>;
  /// The same question for two balls' relative motion.
  { f.straight_pair(ball, other) } -> std::same_as<bool>;
  /// The field's acceleration along the unit normal n of the ball flying at v (the rest threshold
  /// when it bounces off an obstacle; a magnetic force would depend on v).
  { f.normal_accel(ball, v, x) } -> std::same_as<double>;
  /// The ball's potential energy per unit mass at x (energy()).
  { f.potential(ball, x) } -> std::same_as<double>;
  /// Whether balls fly curves whose times of impact need a finite horizon (the bracketed
  /// searches): then a prediction looks no further than the cell exit (or the re-plan time the
  /// flight's cell_exit gives, direction kReplan), and a cell crossing predicts afresh in the whole
  /// new neighbourhood instead of keeping the old prediction beside the new strip's.
  { F::kBoundedHorizon } -> std::convertible_to<bool>;
};

/// A cell "exit" that is a re-plan: the body stays in its cell and predicts afresh.
inline constexpr std::uint8_t kReplan = 4;

/// Straight-line flight: no field acts between events.
struct FreeFlight {
  static constexpr std::string_view kName = "free";
  static constexpr bool kBoundedHorizon = false;
  static bool fits(const WorldDef& def) {
    return def.effects.gravity.x == 0.0 && def.effects.gravity.y == 0.0 && !charges_feel_fields(def);
  }
  FreeFlight() = default;
  explicit FreeFlight(const WorldDef&) {}

  Vec2 pos(std::uint32_t, Vec2 x, Vec2 v, double dt) const { return x + dt * v; }
  Vec2 vel(std::uint32_t, Vec2 v, double) const { return v; }
  CellExit cell_exit(std::uint32_t, Vec2 x, Vec2 v, const CellBox& b) const {
    return earlier_exit(straight_exit(x.x, v.x, b.x_lo, b.x_hi), straight_exit(x.y, v.y, b.y_lo, b.y_hi));
  }
  double toi_balls(std::uint32_t, std::uint32_t, Vec2 r, Vec2 vi, Vec2 vj, double sigma, double) const {
    return toi_disc_disc(r, vj - vi, sigma);
  }
  double toi_point(std::uint32_t, Vec2 rel, Vec2 v, Vec2, double sigma, double) const {
    return toi_disc_point(rel, v, sigma);
  }
  double toi_segment(std::uint32_t, Vec2 rel, Vec2 v, Vec2, const Segment& s, double radius, double) const {
    return toi_disc_segment(rel, v, Vec2{}, s, radius);
  }
  double toi_deforming_segment(std::uint32_t, Vec2 rel, Vec2 v, Vec2 d0, Vec2 w, double radius, double t_max) const {
    return toi_disc_deforming_segment(rel, v, Vec2{}, d0, w, radius, t_max);
  }
  static constexpr bool straight(std::uint32_t) { return true; }
  static constexpr bool straight_pair(std::uint32_t, std::uint32_t) { return true; }
  static constexpr double normal_accel(std::uint32_t, Vec2, Vec2) { return 0.0; }
  static constexpr double potential(std::uint32_t, Vec2) { return 0.0; }
};

/// A cell "exit" that ends a sliding flight: the ball's foot has reached an end of its wall.
inline constexpr std::uint8_t kSlideEnd = 5;

/// A ball sliding along a fixed wall (docs/physics.md, "The sliding flight"): the exact limit of
/// the Zeno sequence of ever lower bounces of a ball the field presses onto the wall at e < 1.
struct Slide {
  Vec2 a;           ///< the field's acceleration along the wall, g - (g.n) n
  Segment s;        ///< the wall's line, to leave it at an end
  Vec2 p2;          ///< the wall's second end, as its ends are stored (s.p1 is the first)
  std::uint32_t wall = kNone;  ///< kNone: not sliding
};

/// Parabolic flight under a uniform acceleration shared by all balls (gravity), but for the balls
/// that slide along a wall (Slide), whose acceleration is the field's part along it.
struct GravityFlight {
  static constexpr std::string_view kName = "gravity";
  static constexpr bool kBoundedHorizon = false;
  static bool fits(const WorldDef& def) { return !charges_feel_fields(def); }
  GravityFlight() = default;
  explicit GravityFlight(const WorldDef& def) : a(def.effects.gravity) {}

  Vec2 a{};
  /// Ball `ball`'s acceleration: the field's, or along its wall while it slides. (One compare
  /// while no ball slides: the gas pays nothing more.)
  Vec2 accel(std::uint32_t ball) const {
    if (sliding_ == 0) [[likely]] return a;
    return sliding(ball) ? slides_[ball].a : a;
  }
  Vec2 pos(std::uint32_t ball, Vec2 x, Vec2 v, double dt) const { return x + dt * v + (0.5 * dt * dt) * accel(ball); }
  Vec2 vel(std::uint32_t ball, Vec2 v, double dt) const { return v + dt * accel(ball); }
  CellExit cell_exit(std::uint32_t ball, Vec2 x, Vec2 v, const CellBox& b) const {
    const Vec2 acc = accel(ball);
    CellExit e = earlier_exit(axis_exit(x.x, v.x, acc.x, b.x_lo, b.x_hi), axis_exit(x.y, v.y, acc.y, b.y_lo, b.y_hi));
    if (sliding_ != 0 && sliding(ball)) [[unlikely]] {
      // The slide ends when the foot of the centre leaves the wall: a parabola along its line.
      const Slide& sl = slides_[ball];
      const AxisExit end = axis_exit(dot(x - sl.s.p1, sl.s.u), dot(v, sl.s.u), dot(sl.a, sl.s.u), 0.0, sl.s.len);
      if (end.t < e.t) e = {end.t, kSlideEnd};
    }
    return e;
  }
  /// Both balls fall alike, so their relative motion is a straight line; a sliding ball's is a
  /// parabola relative to a falling one (the quartic of a disc and an accelerating point).
  double toi_balls(std::uint32_t i, std::uint32_t j, Vec2 r, Vec2 vi, Vec2 vj, double sigma, double t_max) const {
    if (sliding_ != 0) [[unlikely]] {
      const Vec2 ai = accel(i), aj = accel(j);
      if (!(ai == aj)) return toi_disc_point_accel(-r, vi - vj, ai - aj, sigma, t_max);
    }
    return toi_disc_disc(r, vj - vi, sigma);
  }
  double toi_point(std::uint32_t ball, Vec2 rel, Vec2 v, Vec2, double sigma, double t_max) const {
    return toi_disc_point_accel(rel, v, accel(ball), sigma, t_max);
  }
  double toi_segment(std::uint32_t ball, Vec2 rel, Vec2 v, Vec2, const Segment& s, double radius, double) const {
    return toi_disc_segment(rel, v, accel(ball), s, radius);
  }
  double toi_deforming_segment(std::uint32_t ball, Vec2 rel, Vec2 v, Vec2 d0, Vec2 w, double radius, double t_max) const {
    return toi_disc_deforming_segment(rel, v, accel(ball), d0, w, radius, t_max);
  }
  static constexpr bool straight(std::uint32_t) { return false; }
  bool straight_pair(std::uint32_t i, std::uint32_t j) const { return sliding_ == 0 || accel(i) == accel(j); }
  double normal_accel(std::uint32_t ball, Vec2, Vec2 n) const { return dot(accel(ball), n); }
  /// The field's potential: a sliding ball's too (the wall's reaction does no work).
  double potential(std::uint32_t, Vec2 x) const { return -dot(a, x); }

  /// Whether ball `ball` slides now, and along which wall (kNone: it does not).
  bool sliding(std::uint32_t ball) const { return ball < slides_.size() && slides_[ball].wall != kNone; }
  std::uint32_t slide_wall(std::uint32_t ball) const { return sliding(ball) ? slides_[ball].wall : kNone; }
  const Slide& slide(std::uint32_t ball) const { return slides_[ball]; }
  /// Ball `ball` (brought to now, touching wall `wall` on the side of unit normal n, its velocity
  /// along the wall) slides along it from now on.
  void start_slide(std::uint32_t ball, std::uint32_t wall, const Segment& s, Vec2 p2, Vec2 n) {
    if (slides_.size() <= ball) slides_.resize(ball + 1);
    if (slides_[ball].wall == kNone) ++sliding_;
    slides_[ball] = {a - dot(a, n) * n, s, p2, wall};
  }
  /// Ball `ball` (brought to now) flies under the field again.
  void end_slide(std::uint32_t ball) {
    if (!sliding(ball)) return;
    slides_[ball].wall = kNone;
    --sliding_;
  }
  /// Every ball's slide, by ball index (a saved engine state, saved_state.hpp), and the same put back.
  const std::vector<Slide>& slides() const { return slides_; }
  void restore_slides(std::vector<Slide> slides) {
    slides_ = std::move(slides);
    sliding_ = 0;
    for (const Slide& s : slides_) sliding_ += s.wall != kNone ? 1 : 0;
  }

 private:
  std::vector<Slide> slides_;  ///< by ball index, grown at a ball's first slide
  std::uint32_t sliding_ = 0;  ///< how many balls slide now
};

/// Whether body i slides along wall w (only a GravityFlight's balls ever slide).
template <class F>
inline bool slides_on(const F& f, std::uint32_t i, std::uint32_t w) {
  if constexpr (requires { f.slide_wall(i); }) return f.slide_wall(i) == w && w != kNone;
  else return false;
}

/// Whether body i slides along a wall one of whose ends is p (it cannot meet them while it slides).
template <class F>
inline bool slides_to(const F& f, std::uint32_t i, Vec2 p) {
  if constexpr (requires { f.slide(i); }) {
    if (!f.sliding(i)) return false;
    const Slide& s = f.slide(i);
    return p == s.s.p1 || p == s.p2;
  } else {
    return false;
  }
}

/// Flight under gravity, electric and magnetic fields (field_flight.hpp, field_toi.hpp): each ball
/// flies a parabola, a circle or a trochoid, by its charge-to-mass ratio. Balls are grouped into
/// species of equal (a, w), a = g + (q/m) E and w = q Bz / m, kept here by ball index (built only
/// for the scenes that need this flight: Record stays 128 bytes); species 0 is the uncharged {g, 0}.
///   - Pairs of one species: the relative motion is a rotation, closed form (22 ns). Pairs of
///     different species: the bracketed search, which needs a finite horizon (kBoundedHorizon).
///   - An uncharged ball (w == 0) takes today's parabola and today's time-of-impact functions.
///   - A moving point or a translating wall at u: the ball's flight in its frame has a + w J(u)
///     (E' = E + u x B), in_moving_frame. Rotating or deforming walls under B: refused by
///     validate() (no solver); with w == 0 the parabola's deforming-segment solver.
///   - "Just collided, skip this pair" holds only for straight relative motion (the field
///     functions never return the contact just resolved, so not skipping is always safe).
class ChargedFlight {
 public:
  static constexpr std::string_view kName = "fields";
  static constexpr bool kBoundedHorizon = true;
  static bool fits(const WorldDef&) { return true; }
  ChargedFlight() = default;
  explicit ChargedFlight(const WorldDef& def);

  struct Species {
    Vec2 a;          ///< g + (q/m) E
    double w = 0.0;  ///< q Bz / m
    bool circle = false;  ///< w != 0 and a == 0: a drift-free circle (circle_advance)
    double period = 0.0;  ///< gyration_period(w), seconds (kNever when w == 0): cell_exit's horizons
  };
  const Species& species(std::uint32_t ball) const { return species_[of_[ball]]; }
  std::size_t species_count() const { return species_.size(); }
  FieldFlight flight(std::uint32_t ball, Vec2 v) const {
    const Species& s = species(ball);
    return {v, s.a, s.w};
  }

  Vec2 pos(std::uint32_t ball, Vec2 x, Vec2 v, double dt) const {
    const Species& s = species(ball);
    if (s.w == 0.0) return x + dt * v + (0.5 * dt * dt) * s.a;
    if (s.circle) return circle_advance(x, v, s.w, dt).x;
    return x + field_displacement({v, s.a, s.w}, dt);
  }
  Vec2 vel(std::uint32_t ball, Vec2 v, double dt) const {
    const Species& s = species(ball);
    if (s.w == 0.0) return v + dt * s.a;
    if (s.circle) return circle_advance({}, v, s.w, dt).v;
    return field_velocity({v, s.a, s.w}, dt);
  }
  /// pos and vel together, from one set of coefficients (one sine and cosine instead of two): the
  /// same expressions, so the same bits, as the two calls.
  FieldState state(std::uint32_t ball, Vec2 x, Vec2 v, double dt) const {
    const Species& s = species(ball);
    if (s.w == 0.0) return {x + dt * v + (0.5 * dt * dt) * s.a, v + dt * s.a};
    if (s.circle) return circle_advance(x, v, s.w, dt);
    return field_advance(x, {v, s.a, s.w}, dt);
  }
  CellExit cell_exit(std::uint32_t ball, Vec2 x, Vec2 v, const CellBox& b) const;
  double toi_balls(std::uint32_t i, std::uint32_t j, Vec2 r, Vec2 vi, Vec2 vj, double sigma, double t_max) const {
    const Species& si = species(i);
    if (of_[i] == of_[j]) return toi_field_disc_disc_rotating(r, vj - vi, si.w, sigma, t_max);
    const Species& sj = species(j);
    return toi_field_disc_disc(r, {vi, si.a, si.w}, {vj, sj.a, sj.w}, sigma, t_max);
  }
  double toi_point(std::uint32_t ball, Vec2 rel, Vec2 v, Vec2 u, double sigma, double t_max) const {
    const Species& s = species(ball);
    if (s.w == 0.0) return s.a == Vec2{} ? toi_disc_point(rel, v, sigma) : toi_disc_point_accel(rel, v, s.a, sigma, t_max);
    return toi_field_disc_point(rel, {v, s.a + s.w * turn_cw(u), s.w}, sigma, t_max);
  }
  double toi_segment(std::uint32_t ball, Vec2 rel, Vec2 v, Vec2 u, const Segment& seg, double radius,
                     double t_max) const {
    const Species& s = species(ball);
    if (s.w == 0.0) return toi_disc_segment(rel, v, s.a, seg, radius);
    return toi_field_disc_segment(rel, {v, s.a + s.w * turn_cw(u), s.w}, seg, radius, t_max);
  }
  double toi_deforming_segment(std::uint32_t ball, Vec2 rel, Vec2 v, Vec2 d0, Vec2 w, double radius, double t_max) const;
  bool straight(std::uint32_t ball) const {
    const Species& s = species(ball);
    return s.w == 0.0 && s.a == Vec2{};
  }
  bool straight_pair(std::uint32_t i, std::uint32_t j) const {
    const Species& si = species(i);
    const Species& sj = species(j);
    return si.w == 0.0 && sj.w == 0.0 && si.a == sj.a;
  }
  /// a.n + w n.J(v): the magnetic part depends only on v's tangential part, which a bounce keeps,
  /// so this is also the pull on the ball's flight after the bounce.
  double normal_accel(std::uint32_t ball, Vec2 v, Vec2 n) const {
    const Species& s = species(ball);
    return dot(s.a + s.w * turn_cw(v), n);
  }
  double potential(std::uint32_t ball, Vec2 x) const { return -dot(species(ball).a, x); }
  /// Every time of impact the scene can ask for is a closed form that needs no horizon (one species
  /// of drift-free circles among fixed walls): then predictions look as far as they like, and a
  /// cell crossing keeps the old prediction and looks only at the strip of cells it brings into
  /// the neighbourhood, as with straight flights (engine.hpp, exact_clock.hpp).
  bool closed_forms() const { return closed_forms_; }

 private:
  std::vector<Species> species_;
  std::vector<std::uint32_t> of_;  ///< each ball's species
  /// Some pair needs the bracketed search (two species, or a charged ball and turtles): then a
  /// drift-free circle that never leaves its cell re-plans every few periods (cell_exit).
  bool bracketed_pairs_ = false;
  bool closed_forms_ = false;
};

static_assert(Flight<FreeFlight> && Flight<GravityFlight> && Flight<ChargedFlight>);

/// How every body flies: balls by the scene's flight, turtles (ids from `balls` on, kExtras only)
/// always in straight lines. The one place where motion tells balls and turtles apart.

/// A flight's position and velocity after dt together: its state() when it has one (the charged
/// flight's shares the trigonometry), else pos() and vel().
template <class F>
FieldState flight_state(const F& f, std::uint32_t ball, Vec2 x, Vec2 v, double dt) {
  if constexpr (requires { f.state(ball, x, v, dt); }) return f.state(ball, x, v, dt);
  else return {f.pos(ball, x, v, dt), f.vel(ball, v, dt)};
}

/// The field flight of ball `ball` under flight f with velocity v now (FieldFlight's a and w): for
/// the pair searches of a ball against a turtle on an arc.
template <class F>
FieldFlight field_flight_of(const F& f, std::uint32_t ball, Vec2 v) {
  if constexpr (requires { f.flight(ball, v); }) return f.flight(ball, v);
  else if constexpr (requires { f.accel(ball); }) return {v, f.accel(ball), 0.0};
  else return {v, Vec2{}, 0.0};
}

template <Flight F, bool kExtras>
class Motion {
 public:
  Motion() = default;
  explicit Motion(const WorldDef& def) : flight_(def), balls_(static_cast<std::uint32_t>(def.balls.size())) {}

  const F& flight() const { return flight_; }
  F& flight() { return flight_; }
  bool is_turtle(std::uint32_t id) const { return kExtras && id >= balls_; }
  /// A ball spawned at run time takes id balls_ (world_changes.hpp; flights with per-ball data refuse).
  void add_ball() { ++balls_; }
  /// Whether body id's motion relative to something that flies straight is a straight line.
  bool straight(std::uint32_t id) const { return is_turtle(id) ? !arcs(id) : flight_.straight(id); }

  // Turtles on arcs (TurtleCommand::Kind::arc): a turtle driving at v while its heading turns at
  // w rad/s (positive clockwise) flies the drift-free circle of a charged disc in a magnetic field
  // with W = w (field_flight.hpp: there too w > 0 turns clockwise), so its positions and its times
  // of impact are that flight's (circle_advance, field_toi.hpp). No turtle on an arc: one compare.

  /// Turtle k (its index among turtles) turns at w rad/s from now (0: it flies straight).
  void set_arc(std::size_t k, double w) {
    if constexpr (kExtras) {
      if (arc_.size() <= k) {
        if (w == 0.0) return;
        arc_.resize(k + 1, 0.0);
      }
      arcing_ += (w != 0.0 ? 1 : 0) - (arc_[k] != 0.0 ? 1 : 0);
      arc_[k] = w;
    }
  }
  /// Body id's turn rate (rad/s): a turtle's on an arc, else 0.
  double arc(std::uint32_t id) const {
    if (arcing_ == 0 || !is_turtle(id)) [[likely]] return 0.0;
    const std::size_t k = id - balls_;
    return k < arc_.size() ? arc_[k] : 0.0;
  }
  bool arcs(std::uint32_t id) const { return arc(id) != 0.0; }
  bool any_arcs() const { return arcing_ != 0; }
  /// Body id's flight as field_toi.hpp takes it, with velocity v now.
  FieldFlight field_flight(std::uint32_t id, Vec2 v) const {
    return is_turtle(id) ? FieldFlight{v, Vec2{}, arc(id)} : field_flight_of(flight_, id, v);
  }
  /// The first contact of bodies i and j (one of them a turtle on an arc), r = x_j - x_i, both
  /// brought to now with velocities vi and vj; horizon finite (an arc's end bounds it).
  double toi_arc_pair(std::uint32_t i, Vec2 vi, std::uint32_t j, Vec2 r, Vec2 vj, double sigma, double horizon) const {
    return toi_field_disc_disc(r, field_flight(i, vi), field_flight(j, vj), sigma, horizon);
  }

  Vec2 pos(const Body& b, std::uint32_t id, double dt) const {
    if (is_turtle(id)) {
      if (const double w = arc(id); w != 0.0) [[unlikely]] return circle_advance(b.x, b.v, w, dt).x;
      return b.x + dt * b.v;
    }
    return flight_.pos(id, b.x, b.v, dt);
  }
  Vec2 vel(const Body& b, std::uint32_t id, double dt) const {
    if (is_turtle(id)) {
      if (const double w = arc(id); w != 0.0) [[unlikely]] return circle_advance(Vec2{}, b.v, w, dt).v;
      return b.v;
    }
    return flight_.vel(id, b.v, dt);
  }
  /// pos and vel at once (a flight with state() computes them together).
  FieldState state(const Body& b, std::uint32_t id, double dt) const {
    if (is_turtle(id)) {
      if (const double w = arc(id); w != 0.0) [[unlikely]] return circle_advance(b.x, b.v, w, dt);
      return {b.x + dt * b.v, b.v};
    }
    return flight_state(flight_, id, b.x, b.v, dt);
  }
  CellExit cell_exit(std::uint32_t id, Vec2 x, Vec2 v, const CellBox& b) const {
    if (is_turtle(id)) {
      if (const double w = arc(id); w != 0.0) [[unlikely]] {
        // ChargedFlight's drift-free circle: the earlier of the two axes' closed forms.
        const BoxExit bx = field_box_exit_drift_free(x, FieldFlight{v, Vec2{}, w}, {b.x_lo, b.y_lo}, {b.x_hi, b.y_hi});
        if (bx.t == kNever) return {};
        return {bx.t, static_cast<std::uint8_t>(bx.axis == 0 ? (bx.upper ? 1 : 0) : (bx.upper ? 3 : 2))};
      }
      return earlier_exit(straight_exit(x.x, v.x, b.x_lo, b.x_hi), straight_exit(x.y, v.y, b.y_lo, b.y_hi));
    }
    return flight_.cell_exit(id, x, v, b);
  }
  /// Body id (a ball or a turtle) at rel from a point that flies straight at u, v relative to it.
  /// A turtle on an arc seen from a point moving at u turns v + u: relative to the point its
  /// flight has the acceleration w J(u) (in_moving_frame).
  double toi_point(std::uint32_t id, Vec2 rel, Vec2 v, Vec2 u, double sigma, double t_max) const {
    if (is_turtle(id)) {
      if (const double w = arc(id); w != 0.0) [[unlikely]]
        return toi_field_disc_point(rel, FieldFlight{v, w * turn_cw(u), w}, sigma, t_max);
      return toi_disc_point(rel, v, sigma);
    }
    return flight_.toi_point(id, rel, v, u, sigma, t_max);
  }
  double toi_segment(std::uint32_t id, Vec2 rel, Vec2 v, Vec2 u, const Segment& s, double radius, double t_max) const {
    if (!is_turtle(id)) return flight_.toi_segment(id, rel, v, u, s, radius, t_max);
    if (const double w = arc(id); w != 0.0) [[unlikely]]
      return toi_field_disc_segment(rel, FieldFlight{v, w * turn_cw(u), w}, s, radius, t_max);
    // A turtle that has turned to drive along a wall it touches moves along it up to the
    // round-off of its heading's sine and cosine against the wall's normal: a graze, not an
    // approach (it would stop the turtle at once; contacts.hpp, kGrazeRate). Moving along the
    // wall's line it never meets the interior (its ends are points of their own).
    if (grazes_line(v, s.n)) return kNever;
    return toi_disc_segment(rel, v, Vec2{}, s, radius);
  }
  /// (A turtle on an arc never meets a turning or stretching wall: the engine refuses arcs in a
  /// scene with one, as ChargedFlight's circles are refused there; there is no solver.)
  double toi_deforming_segment(std::uint32_t id, Vec2 rel, Vec2 v, Vec2 d0, Vec2 w, double radius, double t_max) const {
    return is_turtle(id) ? toi_disc_deforming_segment(rel, v, Vec2{}, d0, w, radius, t_max)
                         : flight_.toi_deforming_segment(id, rel, v, d0, w, radius, t_max);
  }

 private:
  F flight_;
  std::uint32_t balls_ = 0;
  std::vector<double> arc_;  ///< per turtle: its turn rate on an arc (rad/s), grown at the first arc
  std::uint32_t arcing_ = 0;  ///< how many turtles are on an arc now
};

}  // namespace turtlegas::sim::detail
