// SPDX-License-Identifier: MIT
//
// The GAS engine. One class template, instantiated once per combination of the physics a scene
// can ask for (straight flights or parabolas under gravity; ball-ball collisions on or off; exact
// or step mode; extras or not), chosen when the World is built, so nothing is decided per
// collision.
//
// Order of work, exact mode (event-driven):
//   1. Every ball holds one pending prediction: its earliest collision among the objects in its
//      3x3 cell neighbourhood, and the time it leaves its cell. A calendar queue orders balls by
//      the earlier of the two. Balls keep their own local time; a ball is moved only when an event
//      touches it.
//   2. Pop the earliest ball. A collision whose partner ball has changed course since the
//      prediction (its collision counter moved on) is stale: re-predict and go on.
//   3. A collision: bring the ball(s) to the event time, apply the memo's response, bump their
//      counters, log the event, predict afresh for each.
//   4. A cell crossing: move the ball to the next cell (wrap it in a periodic arena, remove it
//      with an `exit` event when it leaves an open arena), look only at the strip of cells that
//      has just come into its neighbourhood, and keep the earlier of that and its old prediction.
//
// Order of work, step mode (the memo's algorithm, AI Memo 272):
//   1. At the start of a step all balls are at the same time. Balls are listed in the cell of their
//      centre. Each ball predicts its earliest collision within the step among the objects in the
//      cells its path can reach (the memo's rule makes that the 3x3 neighbourhood).
//   2. Take the earliest collision in the step, make it happen, re-predict the balls it changed;
//      repeat until no collision is left in the step (steps 2 and 3 of exact mode, without cells).
//   3. Move every ball to the end of the step and apply the field kick v += a dt. Balls outside an
//      open arena exit; a periodic arena wraps them.
//
// kExtras: the scene has turtles, collision layers or moving walls; without them none of these
// costs a thing. Layers are checked on each candidate pair before any time of impact. Moving walls
// live outside the grid: every prediction checks them, in the wall's frame, up to the next
// keyframe, and a keyframe makes every body predict again.
// Turtles are bodies too (ids after the balls', in cell lists of their own): discs of infinite
// mass that fly straight at the velocity their current command gives, never feel fields, and stop
// dead at a contact (or bounce, if asked). The end of a command is one more candidate in a
// turtle's prediction. Commands arrive from the runtime between calls to advance_to.
#include "engine.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>

#include "cell_grid.hpp"
#include "event_queue.hpp"
#include "turtlegas/sim/reference.hpp"
#include "turtlegas/sim/toi.hpp"

namespace turtlegas::sim::detail {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

/// Straight-line flight: no field acts between events.
struct FreeFlight {
  static constexpr bool kAccelerates = false;
  Vec2 a{};
  Vec2 pos(Vec2 x, Vec2 v, double dt) const { return x + dt * v; }
  Vec2 vel(Vec2 v, double) const { return v; }
  static AxisExit exit(double x, double v, double lo, double hi) {
    if (v > 0.0) return {std::max(0.0, (hi - x) / v), true};
    if (v < 0.0) return {std::max(0.0, (lo - x) / v), false};
    return {};
  }
  AxisExit exit_x(double x, double v, double lo, double hi) const { return exit(x, v, lo, hi); }
  AxisExit exit_y(double y, double v, double lo, double hi) const { return exit(y, v, lo, hi); }
};

/// Parabolic flight under a uniform acceleration shared by all balls (gravity).
struct GravityFlight {
  static constexpr bool kAccelerates = true;
  Vec2 a{};
  Vec2 pos(Vec2 x, Vec2 v, double dt) const { return x + dt * v + (0.5 * dt * dt) * a; }
  Vec2 vel(Vec2 v, double dt) const { return v + dt * a; }
  AxisExit exit_x(double x, double v, double lo, double hi) const { return axis_exit(x, v, a.x, lo, hi); }
  AxisExit exit_y(double y, double v, double lo, double hi) const { return axis_exit(y, v, a.y, lo, hi); }
};

/// One ball's state at its own local time t, kept in one cache line for the neighbour scans.
/// (Aligned, so that a body never straddles two lines: the heap gives only 16-byte alignment.)
struct alignas(64) Body {
  Vec2 x;
  Vec2 v;
  double t = 0.0;
  double r = 0.0;
  std::uint32_t count = 0;  ///< bumped whenever the ball changes course
  std::uint32_t cell = kNone;  ///< kNone once the ball has exited
  std::uint32_t next = kNone;  ///< cell list links
  std::uint32_t prev = kNone;
};
static_assert(sizeof(Body) == 64);

/// What a prediction is about. `body` partners are balls or turtles (ids are shared). (The end of a
/// turtle's own command is kept apart: Engine::end_.)
enum class Partner : std::uint8_t { none, body, wall, end, moving_end };

/// A moving wall's pose at a keyframe: its first end and the vector to its second.
struct MoverKey {
  double t = 0.0;  ///< scene time, seconds
  Vec2 p1;
  Vec2 d;
};

/// A wall moving through keyframes: between two poses each end moves in a straight line at
/// constant velocity. When both ends move alike (w == 0) the wall translates at u, and in its own
/// frame every flight is the usual one with v - u (closed forms); otherwise it turns and stretches
/// as well, and contacts with its interior are found by bracketed root finding.
struct Mover {
  std::uint32_t wall = 0;
  std::size_t next = 0;  ///< the keyframe it is heading for (keys.size(): it has stopped)
  Vec2 p1_ref;           ///< its first end at internal time t_ref
  Vec2 d_ref;            ///< second end minus first, at t_ref
  double t_ref = 0.0;
  Vec2 u{};              ///< the first end's velocity, units/s
  Vec2 w{};              ///< d(d_ref)/dt: the second end's velocity minus the first's
  bool rigid() const { return w.x == 0.0 && w.y == 0.0; }
};

/// The earliest predicted collision of a ball, and when it leaves its cell (exact mode); aligned
/// so that it sits in one cache line.
struct alignas(32) Pending {
  double t_coll = kNever;
  double t_cross = kNever;
  std::uint32_t partner = 0;
  std::uint32_t partner_count = 0;
  std::uint32_t last = kNone;  ///< who the body collided with last (last_code), in the padding
  Partner kind = Partner::none;
  std::uint8_t cross_dir = 0;  ///< 0: -x, 1: +x, 2: -y, 3: +y
};
static_assert(sizeof(Pending) == 32);

/// Everything an event reads and writes about its own body, in two adjacent cache lines: serving a
/// body costs one pair of lines instead of a miss in each of four arrays (bodies, predictions,
/// queue nodes, masses) once they outgrow the cache. The four arrays took the same 128 bytes (and
/// `last_` 4 more, now in the padding of `Pending`).
struct alignas(64) Record {
  Body body;
  Pending pending;
  EventQueue::Node node;
  /// A ball's mass. A turtle has none (a ball meets it as a wall of infinite mass): its slot holds
  /// the internal time its command ends (kNever: no command running), which each of its events
  /// reads beside its prediction.
  double mass_or_end = 0.0;
};
static_assert(sizeof(Record) == 128);

/// One field of every record, indexed like the array it replaces.
template <class T, T& (*Field)(Record&)>
class Column {
 public:
  Column() = default;
  Column(Record* first, std::size_t n) : first_(first), n_(n) {}
  T& operator[](std::size_t i) const { return Field(first_[i]); }
  std::size_t size() const { return n_; }

 private:
  Record* first_ = nullptr;
  std::size_t n_ = 0;
};
inline Body& body_of(Record& r) { return r.body; }
inline Pending& pending_of(Record& r) { return r.pending; }
inline double& mass_of(Record& r) { return r.mass_or_end; }
inline double& command_end_of(Record& r) { return r.mass_or_end; }
inline std::uint32_t& last_of(Record& r) { return r.pending.last; }

struct FreeRecords {
  void operator()(Record* p) const { ::operator delete(p, std::align_val_t{alignof(Record)}); }
};

// Who a body collided with last, packed as kind << 29 | index: with straight relative motion a
// pair that has just collided cannot meet again before one of them has another event, so the
// prediction skips it rather than trusting the sign of a round-off-sized approach speed.
constexpr std::uint32_t last_code(Partner k, std::uint32_t index) {
  return (static_cast<std::uint32_t>(k) << 29) | index;
}

/// A turtle's command in progress, in the engine's internal time.
struct TurtleRun {
  TurtleCommand::Kind kind = TurtleCommand::Kind::stop;
  bool coasting = false;  ///< bouncing off after a contact, until the next control step
  bool touched = false;
  double amount = 0.0;
  double t_start = 0.0;  ///< (its end is in the turtle's Record: Engine::end_)
  double heading0 = 0.0;  ///< heading at t_start
  double omega = 0.0;     ///< signed turn rate while turning
  double speed = 0.0;
  double turn_rate = 0.0;
  double bounce = -1.0;
};

double path_length(Vec2 v, double dt) { return norm(v) * dt; }

/// A moving wall's keyframes as the engine keeps them (validate() has checked them). A span that
/// differs from the previous pose's by round-off only (1e-12 of its length) is taken as exactly
/// the previous one, so that a wall meant to translate runs on the translation's closed forms.
std::vector<MoverKey> mover_keys(const WallDef& wd) {
  std::vector<MoverKey> out;
  out.reserve(wd.keys.size());
  Vec2 d_prev = wd.to - wd.from;
  for (const WallKey& key : wd.keys) {
    Vec2 d = key.to - key.from;
    if (norm(d - d_prev) <= 1e-12 * norm(d_prev)) d = d_prev;
    out.push_back({key.t, key.from, d});
    d_prev = d;
  }
  return out;
}

/// The unit vector of a Logo heading (radians; 0 is +y, clockwise). Headings within 1e-9 degrees
/// of a multiple of 90 give the exact axis: cos(pi/2) is 6e-17, not 0, and a turtle that has
/// turned to drive along the wall it touches would otherwise "approach" it at 1e-15 units/s and
/// stop at once.
Vec2 heading_vector(double heading) {
  const double deg = heading * (180.0 / 3.141592653589793);
  const double quarter = std::round(deg / 90.0);
  if (std::abs(deg - 90.0 * quarter) < 1e-9) {
    switch (((static_cast<long long>(quarter) % 4) + 4) % 4) {
      case 0: return {0.0, 1.0};
      case 1: return {1.0, 0.0};
      case 2: return {0.0, -1.0};
      default: return {-1.0, 0.0};
    }
  }
  return {std::sin(heading), std::cos(heading)};
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
class Engine final : public EngineBase {
 public:
  /// Builds the engine for `def`. `release`, when given, is def's own ball list: it is emptied and
  /// its memory freed as soon as the balls have been copied, before the rest of the engine is
  /// allocated, so that the scene and the whole engine never take memory at the same time.
  Engine(const WorldDef& def, std::vector<BallDef>* release);

  void advance_to(double t) override;
  void set_event_log(std::vector<Event>* log) override { log_ = log; }
  double time() const override { return t_base_ + now_; }
  std::size_t ball_count() const override { return nb_; }
  BallState ball(std::size_t i) const override {
    const Body& b = body_[i];
    const double dt = now_ - b.t;
    return {flight_.pos(b.x, b.v, dt), flight_.vel(b.v, dt), b.cell != kNone};
  }
  double radius(std::size_t i) const override { return body_[i].r; }
  double mass(std::size_t i) const override { return mass_[i]; }
  const std::vector<WallDef>& walls() const override { return wall_defs_; }
  std::size_t turtle_count() const override { return run_.size(); }
  TurtleState turtle(std::size_t k) const override;
  double turtle_radius(std::size_t k) const override { return body_[nb_ + k].r; }
  void idle_turtles(std::vector<std::uint32_t>& out) const override {
    for (std::uint32_t k = 0; k < run_.size(); ++k)
      if (busy_[k] == 0) out.push_back(k);
  }
  void prefetch_turtle(std::size_t k) const override {
    // What turtle(k) and command_turtle(k) read first: the turtle's record (two lines) and its
    // command state (which may straddle two).
    if (k >= run_.size()) return;
    const char* rec = reinterpret_cast<const char*>(&body_[nb_ + k]);
    __builtin_prefetch(rec);
    __builtin_prefetch(rec + 64);
    const char* run = reinterpret_cast<const char*>(&run_[k]);
    __builtin_prefetch(run);
    __builtin_prefetch(run + sizeof(TurtleRun) - 1);
  }
  void command_turtle(std::size_t k, const TurtleCommand& command) override;
  std::size_t add_wall(const WallDef& wall) override;
  std::vector<TurtleContact> take_turtle_contacts() override {
    std::vector<TurtleContact> out;
    out.swap(contacts_);
    return out;
  }
  double energy() const override;
  const Stats& stats() const override { return stats_; }
  Overlap measure_overlap() const override;
  Overlap max_contact_overlap() const override { return max_contact_; }
  double cell_size() const override { return std::min(grid_.cell_w(), grid_.cell_h()); }
  int cells_x() const override { return grid_.nx(); }
  int cells_y() const override { return grid_.ny(); }
  Mode mode() const override { return kStep ? Mode::step : Mode::exact; }
  double dt() const override { return dt_; }

 private:
  bool is_turtle(std::uint32_t id) const { return kExtras && id >= nb_; }
  /// Collision layers: whether two bodies, or a body and a wall or wall end, can touch at all.
  bool meets(std::uint32_t i, std::uint32_t j) const {
    // Bodies' layers are fixed at construction; when all are the defaults (which meet), the pair
    // test reads neither (with many turtles layers_[j] is a cache miss per candidate).
    if constexpr (kExtras) return !bodies_layered_ || layers_[i].collides_with(layers_[j]);
    else return true;
  }
  bool meets_wall(std::uint32_t i, std::uint32_t w) const {
    if constexpr (kExtras) return layers_[i].collides_with(wall_layers_[w]);
    else return true;
  }
  bool meets_end(std::uint32_t i, std::uint32_t e) const {
    if constexpr (kExtras) return layers_[i].collides_with(end_layers_[e]);
    else return true;
  }
  void add_end_layers(Vec2 p, const Layers& l);
  Vec2 mover_p1(const Mover& m, double t) const { return m.p1_ref + (t - m.t_ref) * m.u; }
  Vec2 mover_d(const Mover& m, double t) const { return m.d_ref + (t - m.t_ref) * m.w; }
  /// One end of mover m at internal time t (the second through the translation's fixed shape
  /// when it does not turn or stretch), and that end's velocity.
  Vec2 mover_end(const Mover& m, bool second, double t) const {
    const Vec2 p1 = mover_p1(m, t);
    if (!second) return p1;
    const Segment& s = walls_[m.wall];
    return m.rigid() ? p1 + s.len * s.u : p1 + mover_d(m, t);
  }
  static Vec2 mover_end_velocity(const Mover& m, bool second) { return second ? m.u + m.w : m.u; }
  /// The wall of mover m as a segment at internal time t.
  Segment mover_segment(const Mover& m, double t) const {
    if (m.rigid()) {
      Segment s = walls_[m.wall];
      s.p1 = mover_p1(m, t);
      return s;
    }
    const Vec2 p1 = mover_p1(m, t);
    return make_segment(p1, p1 + mover_d(m, t));
  }
  void aim_mover(Mover& m);
  void refresh_next_key();
  void apply_visibility();
  void keyframe();
  void consider_mover(std::uint32_t i, const Body& bi, std::uint32_t mi, Pending& p) const;
  void collide_moving_end(std::uint32_t i, std::uint32_t code);
  /// The acceleration a body flies under: the field for balls, none for turtles.
  Vec2 accel(std::uint32_t id) const { return is_turtle(id) ? Vec2{} : flight_.a; }
  bool straight(std::uint32_t id) const { return !Flight::kAccelerates || is_turtle(id); }
  /// A turtle standing still (balls under a field are never taken for one: this is for turtles).
  static bool at_rest(const Body& b) { return b.v.x == 0.0 && b.v.y == 0.0; }
  Vec2 pos_at(const Body& b, std::uint32_t id, double dt) const {
    return is_turtle(id) ? b.x + dt * b.v : flight_.pos(b.x, b.v, dt);
  }
  Vec2 vel_at(const Body& b, std::uint32_t id, double dt) const {
    return is_turtle(id) ? b.v : flight_.vel(b.v, dt);
  }
  double heading_at(std::size_t k, double t) const {
    const TurtleRun& r = run_[k];
    return r.heading0 + r.omega * (std::min(t, end_[nb_ + k]) - r.t_start);
  }
  Vec2 min_image(Vec2 d) const {
    if (grid_.periodic()) {
      // The arena is at least 3 cells (so 3 diameters) across: the nearest image is the one.
      d.x -= width_ * std::round(d.x / width_);
      d.y -= height_ * std::round(d.y / height_);
    }
    return d;
  }
  /// x - s.p1 for the image of x nearest to the segment. In a periodic arena the minimum image
  /// relative to p1 is the wrong one near the far part of a wall longer than half the arena.
  Vec2 rel_to_segment(Vec2 x, const Segment& s) const {
    Vec2 best = min_image(x - s.p1);
    if (!grid_.periodic()) return best;
    auto distance = [&](Vec2 rel) { return norm(rel - std::clamp(dot(rel, s.u), 0.0, s.len) * s.u); };
    double best_distance = distance(best);
    const Vec2 base = best;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const Vec2 rel = base + Vec2{dx * width_, dy * height_};
        const double d = distance(rel);
        if (d < best_distance) {
          best = rel;
          best_distance = d;
        }
      }
    return best;
  }

  // Bookkeeping.
  void link(std::uint32_t i, std::uint32_t cell);
  void unlink(std::uint32_t i);
  void sync(std::uint32_t i);
  void log(EventKind kind, std::uint32_t a, std::uint32_t b) {
    if (log_) log_->push_back({t_base_ + now_, kind, a, b});
  }
  void note_contact(double depth, double radius) {
    if (depth > max_contact_.depth) max_contact_.depth = depth;
    if (depth / radius > max_contact_.relative) max_contact_.relative = depth / radius;
  }

  // Predict.
  struct CellXY {
    int ix, iy;
  };
  /// Column and row of a cell (one integer division).
  CellXY cell_xy(std::uint32_t cell) const {
    const int c = static_cast<int>(cell), stride = grid_.stride();
    const int iy = c / stride;
    return {c - iy * stride, iy};
  }
  void predict(std::uint32_t i) {
    const CellXY c = cell_xy(body_[i].cell);
    predict(i, c.ix, c.iy);
  }
  /// (ix, iy): the body's cell, passed in where the caller has it.
  void predict(std::uint32_t i, int ix, int iy);
  void predict_strip(std::uint32_t i, int dir, int ix, int iy);
  // Forced inline: these are the innermost loops of every prediction.
  [[gnu::always_inline]] void scan_cell(std::uint32_t i, const Body& bi, int cell, Vec2 shift, Pending& p) const;
  [[gnu::always_inline]] void consider_ball(std::uint32_t i, const Body& bi, std::uint32_t j, Vec2 shift, Pending& p) const;
  void consider_turtle(std::uint32_t i, const Body& bi, std::uint32_t j, Vec2 shift, Pending& p) const;
  void consider_ball_from_turtle(std::uint32_t i, const Body& bi, std::uint32_t j, Vec2 shift, Pending& p) const;
  void consider_wall(std::uint32_t i, const Body& bi, std::uint32_t w, Vec2 shift, Pending& p) const;
  void consider_end(std::uint32_t i, const Body& bi, std::uint32_t e, Vec2 shift, Pending& p) const;
  void predict_crossing(std::uint32_t i) {
    const CellXY c = cell_xy(body_[i].cell);
    predict_crossing(i, c.ix, c.iy);
  }
  void predict_crossing(std::uint32_t i, int ix, int iy);
  /// When a turtle's command ends (kNever for a ball, or a turtle with no command running).
  double command_end(std::uint32_t i) const {
    if constexpr (kExtras) return is_turtle(i) ? end_[i] : kNever;
    else return kNever;
  }
  void schedule(std::uint32_t i) {
    const Pending& p = pending_[i];
    heap_.set(i, std::min(std::min(p.t_coll, p.t_cross), command_end(i)));
  }
  int step_rings(double reach) const {
    return static_cast<int>(std::floor(reach / std::min(grid_.cell_w(), grid_.cell_h()))) + 1;
  }

  // Apply.
  /// Serves events up to internal time `limit`. Returns false when it stopped early to rebase the
  /// clock (exact mode), so that the caller takes the limit afresh in the new internal time.
  bool process(double limit);
  void collide(std::uint32_t i);
  void collide_balls(std::uint32_t i, std::uint32_t j);
  void collide_with_turtle(std::uint32_t i, std::uint32_t j);
  void collide_wall(std::uint32_t i, std::uint32_t w);
  void collide_end(std::uint32_t i, std::uint32_t e);
  void end_command(std::uint32_t i);
  void touch(std::uint32_t id, EventKind kind, std::uint32_t other, Vec2 normal);
  void cross(std::uint32_t i);
  void remove(std::uint32_t i);
  void repredict(std::uint32_t i);
  double restitution_for(std::uint32_t i) const;
  Vec2 bounce(std::uint32_t i, Vec2 v, Vec2 n) const;
  void after_change(std::uint32_t i);

  // Time.
  double rebase();
  void begin_step();
  void finish_step();

  Flight flight_;
  double e_ = 1.0;
  double tc_ = 0.0;
  bool inelastic_ = false;
  Boundary boundary_ = Boundary::none;
  double width_ = 0.0, height_ = 0.0;
  double dt_ = 0.0;
  Vec2 kick_{};

  std::uint32_t nb_ = 0;     ///< balls are ids [0, nb_), turtles [nb_, body_.size())
  std::unique_ptr<Record[], FreeRecords> records_;  ///< one per body; the columns below view them
  Column<Body, body_of> body_;
  Column<double, mass_of> mass_;      ///< balls only
  Column<double, command_end_of> end_;  ///< turtles only: when the command running ends
  Column<std::uint32_t, last_of> last_;
  Column<Pending, pending_of> pending_;
  std::vector<double> last_time_;  ///< only when restitution < 1 (the TC rule)
  std::vector<std::uint32_t> head_;         ///< balls by cell
  std::vector<std::uint32_t> turtle_head_;  ///< turtles by cell (only when there are turtles)
  std::vector<TurtleRun> run_;
  std::vector<std::uint8_t> busy_;  ///< per turtle: a command is running (apart, so the idle scan reads 1 byte a turtle)
  std::vector<TurtleContact> contacts_;
  std::vector<Layers> layers_;       ///< per body (kExtras only)
  bool bodies_layered_ = false;      ///< whether any body's layers differ from the defaults
  std::vector<Layers> wall_layers_;  ///< per wall (kExtras only)
  std::vector<Layers> end_layers_;   ///< per end: its walls' categories and masks together
  std::vector<Mover> movers_;                 ///< moving walls (kExtras only), outside the grid
  std::vector<std::vector<MoverKey>> keys_;   ///< their keyframes, by mover
  std::vector<std::uint32_t> mover_of_;       ///< per wall: its mover, or kNone
  std::vector<std::uint32_t> pushed_by_;      ///< per turtle: the mover pushing it, or kNone
  std::vector<std::uint32_t> blinkers_;       ///< walls whose visibility changes in time
  std::vector<std::size_t> blink_next_;       ///< per blinker: its next visibility key
  std::vector<std::uint32_t> base_mask_;      ///< per wall: its mask while it is there
  double next_key_ = kNever;                  ///< internal time of the next keyframe of any mover
  EventQueue heap_;

  std::vector<WallDef> wall_defs_;
  std::vector<Segment> walls_;
  std::vector<WallEnd> ends_;
  CellGrid grid_;
  double cell_ = 0.0;  ///< the cell side the grid was built for (rebuilt with it when walls are added)

  double now_ = 0.0;     ///< internal time, relative to t_base_
  double t_base_ = 0.0;  ///< external time of internal time zero
  std::uint64_t events_since_rebase_ = 0;
  std::uint64_t rebase_every_ = 0;

  // Step mode.
  std::uint64_t step_index_ = 0;
  double rmax_ = 0.0;
  double dmax_ = 0.0;              ///< largest path length of any body in this step
  std::vector<double> travel_;     ///< path length so far in this step
  mutable std::vector<std::uint32_t> stamp_;  ///< de-duplicates walls and ends in ring scans
  mutable std::uint32_t scan_ = 0;

  Stats stats_;
  Overlap max_contact_;
  std::vector<Event>* log_ = nullptr;
};

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
Engine<Flight, kBallBall, kStep, kExtras>::Engine(const WorldDef& def, std::vector<BallDef>* release) {
  if (auto problem = validate(def)) throw std::invalid_argument(problem->message);
  const EffectsDef& fx = def.effects;
  if constexpr (kStep) kick_ = fx.gravity;
  else flight_.a = fx.gravity;
  e_ = fx.restitution;
  tc_ = fx.tc;
  inelastic_ = e_ < 1.0;
  boundary_ = def.arena.boundary;
  width_ = def.arena.width;
  height_ = def.arena.height;
  dt_ = def.dt;

  wall_defs_ = def.walls;
  if (boundary_ == Boundary::walls)
    for (auto& w : arena_walls(def.arena)) wall_defs_.push_back(w);
  for (const auto& w : wall_defs_) {
    walls_.push_back(make_segment(w.from, w.to));
    if (boundary_ == Boundary::periodic) {
      for (Vec2 p : {w.from, w.to})
        if (p.x < 0.0 || p.x > width_ || p.y < 0.0 || p.y > height_)
          throw std::invalid_argument("wall '" + w.id + "' reaches outside a periodic arena; keep walls inside it");
    }
  }
  // Moving walls are checked by every prediction rather than listed in the table.
  mover_of_.assign(wall_defs_.size(), kNone);
  for (std::uint32_t w = 0; w < wall_defs_.size(); ++w) {
    const WallDef& wd = wall_defs_[w];
    if (wd.keys.empty()) continue;
    if (boundary_ == Boundary::periodic) throw std::invalid_argument("wall '" + wd.id + "' moves: moving walls are not supported in a periodic arena yet");
    mover_of_[w] = static_cast<std::uint32_t>(movers_.size());
    movers_.push_back(Mover{w, 0, wd.from, wd.to - wd.from, 0.0, {}, {}});
    keys_.push_back(mover_keys(wd));
  }
  // Wall ends, one per distinct point: a corner shared by two walls is one collision object.
  for (std::uint32_t w = 0; w < wall_defs_.size(); ++w)
    if (mover_of_[w] == kNone)
      for (Vec2 p : {wall_defs_[w].from, wall_defs_[w].to}) ends_.push_back({p, w});
  std::stable_sort(ends_.begin(), ends_.end(), [](const WallEnd& a, const WallEnd& b) {
    return a.p.x != b.p.x ? a.p.x < b.p.x : a.p.y < b.p.y;
  });
  ends_.erase(std::unique(ends_.begin(), ends_.end(), [](const WallEnd& a, const WallEnd& b) { return a.p == b.p; }),
              ends_.end());

  nb_ = static_cast<std::uint32_t>(def.balls.size());
  const std::size_t n = def.balls.size() + def.turtles.size();
  double vmax = 0.0;
  for (const auto& b : def.balls) {
    rmax_ = std::max(rmax_, b.radius);
    vmax = std::max(vmax, norm(b.vel));
  }
  for (const auto& t : def.turtles) {
    rmax_ = std::max(rmax_, t.radius);
    vmax = std::max(vmax, t.speed);
  }
  // Cell size. Exact mode needs cells at least a diameter wide so that touching bodies are always
  // in neighbouring cells; step mode needs the memo's rule: a cell wider than any two bodies' radii
  // plus their paths in one step.
  const double area = width_ * height_;
  const double rule = kStep ? 2.0 * (rmax_ + vmax * dt_) : 2.0 * rmax_;
  double cell = 0.0;
  if (def.arena.cell) {
    cell = *def.arena.cell;
    if (cell < rule) {
      const std::string why = kStep
          ? "the memo's rule in step mode needs cells wider than twice (largest radius + largest speed x dt) = " +
                std::to_string(rule) + "; set arena.cell >= that, use a smaller dt, or use --mode exact"
          : "exact mode needs cells at least as wide as the largest ball or turtle (diameter " + std::to_string(rule) +
                "); set arena.cell >= that";
      throw std::invalid_argument("arena.cell " + std::to_string(cell) + " is too small: " + why);
    }
  } else {
    double preferred = 0.0;
    if (!kStep && !kBallBall && def.turtles.empty()) {
      // Exact mode, balls meeting walls only: their number says nothing about how fine the table
      // must be, and every cell crossing is an event that finds no partner. (Step mode has no
      // crossing events; there finer cells keep the walls out of most balls' neighbourhoods, so it
      // keeps the rule below.) So size the cells by the walls instead, at about one wall passing
      // through a cell: with total wall length L, L / cell cells are crossed by walls out of
      // area / cell^2, which is one each at cell = area / L. At most a quarter of the arena (a
      // plain box gets a 4 x 4 table); no walls at all (exits only) gives that too.
      double length = 0.0;
      for (std::uint32_t w = 0; w < walls_.size(); ++w)
        if (mover_of_[w] == kNone) length += walls_[w].len;
      const double quarter = std::max(width_, height_) / 4.0;
      preferred = length > 0.0 ? std::min(area / length, quarter) : quarter;
    } else {
      // About 0.3 balls per cell: measured fastest in exact mode from area fraction 0.05 to 0.3
      // (fewer balls per cell means fewer candidates per prediction but more cell crossings).
      preferred = n > 0 ? std::sqrt(0.3 * area / static_cast<double>(n)) : std::max(width_, height_) / 16.0;
    }
    cell = std::max(rule * (1.0 + 1e-9), preferred);
    cell = std::max(cell, std::sqrt(area / 4.0e7));  // keep the table under ~4e7 cells
    // A periodic arena needs three cells across, so that no pair is seen through two images.
    if (boundary_ == Boundary::periodic) cell = std::max(rule * (1.0 + 1e-9), std::min(cell, std::min(width_, height_) / 3.0));
  }
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
  records_.reset(static_cast<Record*>(::operator new(n * sizeof(Record), std::align_val_t{alignof(Record)})));
  char* const raw = reinterpret_cast<char*>(records_.get());
  char* const packed = raw + n * (sizeof(Record) - sizeof(Packed));
  if constexpr (kExtras) {
    layers_.resize(n);
    for (std::uint32_t i = 0; i < nb_; ++i) layers_[i] = def.balls[i].layers;
    for (std::size_t k = 0; k < def.turtles.size(); ++k) layers_[nb_ + k] = def.turtles[k].layers;
    bodies_layered_ = std::any_of(layers_.begin(), layers_.end(), [](const Layers& l) { return l != Layers{}; });
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
  body_ = {records_.get(), n};
  mass_ = {records_.get(), nb_};
  end_ = {records_.get(), n};
  last_ = {records_.get(), n};
  pending_ = {records_.get(), n};
  run_.resize(def.turtles.size());
  busy_.assign(def.turtles.size(), 0);
  for (std::size_t k = 0; k < def.turtles.size(); ++k) {
    const TurtleDef& d = def.turtles[k];
    const auto id = static_cast<std::uint32_t>(nb_ + k);
    body_[id].x = d.pos;
    body_[id].r = d.radius;
    end_[id] = kNever;
    TurtleRun& r = run_[k];
    r.heading0 = d.heading;
    r.speed = d.speed;
    r.turn_rate = d.turn_rate;
    r.bounce = d.bounce;
  }

  const bool periodic = boundary_ == Boundary::periodic;
  cell_ = cell;
  std::vector<bool> moving(wall_defs_.size());
  for (std::uint32_t w = 0; w < wall_defs_.size(); ++w) moving[w] = mover_of_[w] != kNone;
  grid_ = CellGrid(width_, height_, cell, periodic, walls_, ends_, moving);
  if (periodic && (grid_.nx() < 3 || grid_.ny() < 3))
    throw std::invalid_argument("a periodic arena must be at least 3 cells across (cell " + std::to_string(cell) +
                                "); enlarge the arena or use smaller balls");

  if (inelastic_) last_time_.assign(n, -kNever);
  head_.assign(static_cast<std::size_t>(grid_.cell_count()), kNone);
  if constexpr (kExtras) turtle_head_.assign(static_cast<std::size_t>(grid_.cell_count()), kNone);
  heap_.reset(n > 0 ? &records_[0].node : nullptr, sizeof(Record), n);
  if constexpr (kStep) {
    travel_.assign(n, 0.0);
    stamp_.assign(walls_.size() * 9 + ends_.size() * 9, 0);
  }
  if constexpr (kExtras) {
    for (const auto& w : wall_defs_) wall_layers_.push_back(w.layers);
    end_layers_.assign(ends_.size(), Layers{0u, 0u});
    for (const auto& w : wall_defs_)
      for (Vec2 p : {w.from, w.to}) add_end_layers(p, w.layers);
  }
  // Balls, then turtles, each in list order, as the cell lists have always been built.
  for (std::uint32_t i = 0; i < n; ++i) link(i, static_cast<std::uint32_t>(grid_.arena_cell_of(body_[i].x)));
  if constexpr (kExtras) {
    base_mask_.resize(wall_defs_.size());
    for (std::uint32_t w = 0; w < wall_defs_.size(); ++w) {
      base_mask_[w] = wall_layers_[w].mask;
      const auto& vis = wall_defs_[w].visibility;
      if (vis.empty()) continue;
      double prev = -1.0;
      for (const VisibilityKey& k : vis) {
        if (!(k.t > prev) || k.t < 0.0)
          throw std::invalid_argument("wall '" + wall_defs_[w].id + "': visibility times must increase and be >= 0");
        prev = k.t;
      }
      blinkers_.push_back(w);
      blink_next_.push_back(0);
    }
    apply_visibility();
    pushed_by_.assign(def.turtles.size(), kNone);
    for (Mover& m : movers_) aim_mover(m);
    refresh_next_key();
  }
  rebase_every_ = std::max<std::uint64_t>(4 * n, 4096);
  if constexpr (kStep) {
    begin_step();
  } else {
    for (std::uint32_t i = 0; i < n; ++i) {
      predict(i);
      predict_crossing(i);
      schedule(i);
    }
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::link(std::uint32_t i, std::uint32_t cell) {
  Body& b = body_[i];
  std::uint32_t& head = is_turtle(i) ? turtle_head_[cell] : head_[cell];
  b.cell = cell;
  b.prev = kNone;
  b.next = head;
  if (b.next != kNone) body_[b.next].prev = i;
  head = i;
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::unlink(std::uint32_t i) {
  Body& b = body_[i];
  if (b.prev != kNone) body_[b.prev].next = b.next;
  else (is_turtle(i) ? turtle_head_[b.cell] : head_[b.cell]) = b.next;
  if (b.next != kNone) body_[b.next].prev = b.prev;
  b.next = b.prev = kNone;
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::sync(std::uint32_t i) {
  Body& b = body_[i];
  const double dt = now_ - b.t;
  if constexpr (kStep) travel_[i] += path_length(b.v, dt);
  b.x = pos_at(b, i, dt);
  b.v = vel_at(b, i, dt);
  b.t = now_;
}

// ---------------------------------------------------------------------------------------------
// Predict

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
    if (last_[i] == last_code(Partner::body, j) && last_[j] == last_code(Partner::body, i)) return;
    p.t_coll = t;
    p.kind = Partner::body;
    p.partner = j;
    p.partner_count = bj.count;
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
    if (straight(i) && last_[i] == last_code(Partner::body, j) && last_[j] == last_code(Partner::body, i)) return;
    p.t_coll = t;
    p.kind = Partner::body;
    p.partner = j;
    p.partner_count = bj.count;
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::consider_wall(std::uint32_t i, const Body& bi, std::uint32_t w,
                                                               Vec2 shift, Pending& p) const {
  if (!meets_wall(i, w) || (straight(i) && last_[i] == last_code(Partner::wall, w))) return;
  const Segment& s = walls_[w];
  // Relative to the wall's first end, so walls far from the origin lose nothing.
  const double t = now_ + toi_disc_segment(bi.x - (s.p1 + shift), bi.v, accel(i), s, bi.r);
  if (t < p.t_coll) {
    p.t_coll = t;
    p.kind = Partner::wall;
    p.partner = w;
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::consider_end(std::uint32_t i, const Body& bi, std::uint32_t e,
                                                              Vec2 shift, Pending& p) const {
  if (!meets_end(i, e) || (straight(i) && last_[i] == last_code(Partner::end, e))) return;
  const Vec2 rel = bi.x - (ends_[e].p + shift);
  double dt;
  if (Flight::kAccelerates && !is_turtle(i)) dt = toi_disc_point_accel(rel, bi.v, flight_.a, bi.r, p.t_coll - now_);
  else dt = toi_disc_point(rel, bi.v, bi.r);
  const double t = now_ + dt;
  if (t < p.t_coll) {
    p.t_coll = t;
    p.kind = Partner::end;
    p.partner = e;
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
    if (!Flight::kAccelerates && last_[i] == last_code(Partner::body, j) && last_[j] == last_code(Partner::body, i)) return;
    p.t_coll = t;
    p.kind = Partner::body;
    p.partner = j;
    p.partner_count = bj.count;
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
inline void Engine<Flight, kBallBall, kStep, kExtras>::scan_cell(std::uint32_t i, const Body& bi, int cell, Vec2 shift,
                                                           Pending& p) const {
  // The bodies listed in one cell: balls (when the pair can collide) and turtles.
  if (!is_turtle(i)) {
    if constexpr (kBallBall)
      for (std::uint32_t j = head_[cell]; j != kNone; j = body_[j].next) consider_ball(i, bi, j, shift, p);
  } else if (nb_ > 0) {  // a scene of turtles alone never reads the (empty) ball lists
    for (std::uint32_t j = head_[cell]; j != kNone; j = body_[j].next) consider_ball_from_turtle(i, bi, j, shift, p);
  }
  if constexpr (kExtras)
    for (std::uint32_t j = turtle_head_[cell]; j != kNone; j = body_[j].next) consider_turtle(i, bi, j, shift, p);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::predict(std::uint32_t i, int ix, int iy) {
  const Body& bi = body_[i];
  Pending& p = pending_[i];
  // A turtle's command end is not a candidate here: it is kept apart (command_end()), so that a
  // turtle whose command starts or ends without moving it keeps the collisions predicted for it.
  p.t_coll = kNever;
  p.kind = Partner::none;
  if constexpr (!kStep) {
    if (grid_.plain_neighbourhood(ix, iy)) {
      // Away from a periodic seam the 3x3 cells are three runs of three in the table.
      const int stride = grid_.stride();
      if constexpr (kExtras) {
        // Scenes with turtles: the first body listed in each of the nine cells is asked for
        // before the scan walks the lists one by one (with many turtles each is a cache miss).
        for (int row = static_cast<int>(bi.cell) - stride - 1, dy = -1; dy <= 1; ++dy, row += stride)
          for (int dx = 0; dx <= 2; ++dx) {
            if (const std::uint32_t j = turtle_head_[row + dx]; j != kNone) __builtin_prefetch(&body_[j]);
            if (nb_ == 0) continue;
            if (const std::uint32_t j = head_[row + dx]; j != kNone) __builtin_prefetch(&body_[j]);
          }
      }
      for (int row = static_cast<int>(bi.cell) - stride - 1, dy = -1; dy <= 1; ++dy, row += stride)
        for (int dx = 0; dx <= 2; ++dx) scan_cell(i, bi, row + dx, Vec2{}, p);
    } else {
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto nb = grid_.neighbour(ix, iy, dx, dy);
          scan_cell(i, bi, nb.cell, nb.shift, p);
        }
    }
    for (auto it = grid_.near_walls_begin(bi.cell); it != grid_.near_walls_end(bi.cell); ++it)
      consider_wall(i, bi, it->item, grid_.shift(it->shift), p);
    for (auto it = grid_.near_ends_begin(bi.cell); it != grid_.near_ends_end(bi.cell); ++it)
      consider_end(i, bi, it->item, grid_.shift(it->shift), p);
    if constexpr (kExtras)
      for (std::uint32_t m = 0; m < movers_.size(); ++m) consider_mover(i, bi, m, p);
  } else {
    // The memo's rule normally makes this the 3x3 neighbourhood; a body sped up by a collision
    // inside the step widens the search instead of missing a partner.
    const double step_end = dt_;
    const double d_i = travel_[i] + path_length(bi.v, step_end - now_);
    dmax_ = std::max(dmax_, d_i);
    const int kb = step_rings(bi.r + rmax_ + d_i + dmax_);
    const int kw = step_rings(bi.r + d_i);
    const bool periodic = grid_.periodic();
    if (periodic && (2 * kb + 1 > grid_.nx() || 2 * kb + 1 > grid_.ny()))
      throw std::runtime_error("step mode: a body moves too far in one step for this periodic arena; use a smaller dt or --mode exact");
    for (int dy = -kb; dy <= kb; ++dy)
      for (int dx = -kb; dx <= kb; ++dx) {
        if (!periodic && (ix + dx < 1 || ix + dx > grid_.nx() || iy + dy < 1 || iy + dy > grid_.ny())) continue;
        const auto nb = grid_.neighbour(ix, iy, dx, dy);
        scan_cell(i, bi, nb.cell, nb.shift, p);
      }
    ++scan_;
    for (int dy = -kw; dy <= kw; ++dy)
      for (int dx = -kw; dx <= kw; ++dx) {
        if (!periodic && (ix + dx < 0 || ix + dx > grid_.nx() + 1 || iy + dy < 0 || iy + dy > grid_.ny() + 1)) continue;
        const auto nb = grid_.neighbour(ix, iy, dx, dy);
        const std::uint32_t s = grid_.shift_index(nb.shift);
        for (auto it = grid_.walls_begin(nb.cell); it != grid_.walls_end(nb.cell); ++it) {
          std::uint32_t& st = stamp_[*it * 9 + s];
          if (st == scan_) continue;
          st = scan_;
          consider_wall(i, bi, *it, nb.shift, p);
        }
        for (auto it = grid_.ends_begin(nb.cell); it != grid_.ends_end(nb.cell); ++it) {
          std::uint32_t& st = stamp_[walls_.size() * 9 + *it * 9 + s];
          if (st == scan_) continue;
          st = scan_;
          consider_end(i, bi, *it, nb.shift, p);
        }
      }
    if constexpr (kExtras)
      for (std::uint32_t m = 0; m < movers_.size(); ++m) consider_mover(i, bi, m, p);
    if (p.t_coll > step_end) {
      p.t_coll = kNever;
      p.kind = Partner::none;
    }
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::predict_strip(std::uint32_t i, int dir, int ix, int iy) {
  // The three cells that have just come within the 3x3 neighbourhood after a crossing in `dir`.
  const Body& bi = body_[i];
  Pending& p = pending_[i];
  const int ax = dir == 0 ? -1 : (dir == 1 ? 1 : 0);
  const int ay = dir == 2 ? -1 : (dir == 3 ? 1 : 0);
  int cells[3];
  Vec2 shifts[3] = {};
  if (grid_.plain_neighbourhood(ix, iy)) {
    // Three cells in a row (step 1) or a column (step stride) of the table.
    const int step = ax != 0 ? grid_.stride() : 1;
    const int middle = grid_.index(ix + ax, iy + ay);
    cells[0] = middle - step;
    cells[1] = middle;
    cells[2] = middle + step;
  } else {
    for (int k = -1; k <= 1; ++k) {
      const auto nb = grid_.neighbour(ix, iy, ax != 0 ? ax : k, ay != 0 ? ay : k);
      cells[k + 1] = nb.cell;
      shifts[k + 1] = nb.shift;
    }
  }
  for (int k = 0; k < 3; ++k) {
    const int cell = cells[k];
    scan_cell(i, bi, cell, shifts[k], p);
    if (!grid_.has_walls(cell)) continue;
    for (auto it = grid_.walls_begin(cell); it != grid_.walls_end(cell); ++it) consider_wall(i, bi, *it, shifts[k], p);
    for (auto it = grid_.ends_begin(cell); it != grid_.ends_end(cell); ++it) consider_end(i, bi, *it, shifts[k], p);
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::predict_crossing(std::uint32_t i, int ix, int iy) {
  const Body& b = body_[i];
  Pending& p = pending_[i];
  // Relative to the cell's edges, computed from the cell index rather than re-derived from the
  // position, so a body sitting on an edge by round-off is never assigned twice.
  AxisExit ex, ey;
  if (is_turtle(i)) {
    ex = FreeFlight::exit(b.x.x, b.v.x, grid_.x_line(ix - 1), grid_.x_line(ix));
    ey = FreeFlight::exit(b.x.y, b.v.y, grid_.y_line(iy - 1), grid_.y_line(iy));
  } else {
    ex = flight_.exit_x(b.x.x, b.v.x, grid_.x_line(ix - 1), grid_.x_line(ix));
    ey = flight_.exit_y(b.x.y, b.v.y, grid_.y_line(iy - 1), grid_.y_line(iy));
  }
  if (ex.t <= ey.t) {
    p.t_cross = now_ + ex.t;
    p.cross_dir = ex.upper ? 1 : 0;
  } else {
    p.t_cross = now_ + ey.t;
    p.cross_dir = ey.upper ? 3 : 2;
  }
}

// ---------------------------------------------------------------------------------------------
// Apply

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
bool Engine<Flight, kBallBall, kStep, kExtras>::process(double limit) {
  for (;;) {
    const double next_event = heap_.empty() ? kNever : heap_.top_key();
    if constexpr (kExtras) {
      // A moving wall reaching a keyframe changes course: everything predicts again.
      if (next_key_ <= limit && next_key_ <= next_event) {
        keyframe();
        continue;
      }
    }
    if (next_event > limit) break;
    const std::uint32_t i = heap_.top_id();
    now_ = heap_.top_key();
    ++stats_.events;
    // The next events most likely belong to the top's children in the served bucket (or to the
    // next bucket): start loading their state now, which hides a cache miss or two per event once
    // the bodies outgrow the cache. (Written out rather than through a callback: GCC 12 drops the
    // prefetches of a lambda that does nothing else.)
    for (std::size_t n = 0; n < 2; ++n) {
      const std::uint32_t k = heap_.next_id(n);
      if (k == EventQueue::kAbsent) continue;
      __builtin_prefetch(&body_[k]);
      __builtin_prefetch(&pending_[k]);
    }
    const Pending& p = pending_[i];
    // A command's end goes first at a tie with a collision or a crossing.
    if (const double t_end = command_end(i); t_end <= p.t_coll && t_end <= p.t_cross) end_command(i);
    else if (p.t_coll <= p.t_cross) collide(i);
    else cross(i);
    if constexpr (!kStep) {
      if (++events_since_rebase_ >= rebase_every_) {
        rebase();
        return false;
      }
    }
  }
  return true;
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::repredict(std::uint32_t i) {
  const CellXY c = cell_xy(body_[i].cell);
  predict(i, c.ix, c.iy);
  if constexpr (!kStep) predict_crossing(i, c.ix, c.iy);  // crossing times depend on the velocity just changed
  schedule(i);
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
void Engine<Flight, kBallBall, kStep, kExtras>::after_change(std::uint32_t i) {
  ++body_[i].count;
  if (inelastic_) last_time_[i] = now_;
  if constexpr (kStep) {
    // The rest of the step is walked at the new speed.
    dmax_ = std::max(dmax_, travel_[i] + path_length(body_[i].v, dt_ - now_));
  }
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
  last_[i] = last_code(Partner::body, j);
  last_[j] = last_code(Partner::body, i);
  repredict(i);
  repredict(j);
}

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
  last_[t] = last_code(Partner::body, o);
  last_[o] = last_code(Partner::body, t);
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
  last_[i] = last_code(Partner::wall, w);
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
  last_[i] = last_code(Partner::end, e);
  repredict(i);
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
  last_[i] = kNone;
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
  last_[id] = kNone;
  if constexpr (kStep) dmax_ = std::max(dmax_, travel_[id] + path_length(b.v, dt_ - now_));
  repredict(id);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::aim_mover(Mover& m) {
  // From where it is now (at t_ref) towards its next pose, arriving at that pose's time.
  const auto& keys = keys_[mover_of_[m.wall]];
  if (m.next >= keys.size()) {
    m.u = {};
    m.w = {};
  } else {
    const double t_key = keys[m.next].t - t_base_;
    m.u = (keys[m.next].p1 - m.p1_ref) / (t_key - m.t_ref);
    // Exactly zero when the pose keeps its span: the translation's closed forms apply.
    m.w = keys[m.next].d == m.d_ref ? Vec2{} : (keys[m.next].d - m.d_ref) / (t_key - m.t_ref);
  }
  refresh_next_key();
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::refresh_next_key() {
  // Always from the keyframes' own times and the current base, never by shifting the old value:
  // keyframe() must find, at next_key_, the very keyframe that set it.
  next_key_ = kNever;
  for (const Mover& o : movers_) {
    const auto& k = keys_[mover_of_[o.wall]];
    if (o.next < k.size()) next_key_ = std::min(next_key_, k[o.next].t - t_base_);
  }
  for (std::size_t b = 0; b < blinkers_.size(); ++b) {
    const auto& vis = wall_defs_[blinkers_[b]].visibility;
    if (blink_next_[b] < vis.size()) next_key_ = std::min(next_key_, vis[blink_next_[b]].t - t_base_);
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::apply_visibility() {
  // Take every visibility key that is due, then rebuild the ends' layers (an end is there when any
  // of its walls is).
  bool changed = false;
  for (std::size_t b = 0; b < blinkers_.size(); ++b) {
    const std::uint32_t w = blinkers_[b];
    const auto& vis = wall_defs_[w].visibility;
    while (blink_next_[b] < vis.size() && !(vis[blink_next_[b]].t - t_base_ > now_)) {
      wall_layers_[w].mask = vis[blink_next_[b]].visible ? base_mask_[w] : 0u;
      ++blink_next_[b];
      changed = true;
    }
  }
  if (!changed) return;
  std::fill(end_layers_.begin(), end_layers_.end(), Layers{0u, 0u});
  for (std::uint32_t w = 0; w < wall_defs_.size(); ++w)
    if (mover_of_[w] == kNone)
      for (Vec2 p : {wall_defs_[w].from, wall_defs_[w].to}) add_end_layers(p, wall_layers_[w]);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::keyframe() {
  now_ = next_key_;
  ++stats_.events;
  for (Mover& m : movers_) {
    const auto& keys = keys_[mover_of_[m.wall]];
    if (m.next < keys.size() && !(keys[m.next].t - t_base_ > now_)) {
      m.p1_ref = keys[m.next].p1;  // exactly the keyframe's pose
      if (keys[m.next].d != m.d_ref) {
        m.d_ref = keys[m.next].d;
        walls_[m.wall] = make_segment(m.p1_ref, m.p1_ref + m.d_ref);  // the shape translations use
      }
      m.t_ref = now_;
      ++m.next;
    }
  }
  apply_visibility();
  for (Mover& m : movers_) aim_mover(m);
  refresh_next_key();
  for (std::uint32_t i = 0; i < body_.size(); ++i) {
    if (body_[i].cell == kNone) continue;
    sync(i);
    if (is_turtle(i) && pushed_by_[i - nb_] != kNone) {
      // The push ends with the segment of motion that made it; the turtle stands where it is.
      body_[i].v = {};
      pushed_by_[i - nb_] = kNone;
      ++body_[i].count;
    }
    // "Just collided, cannot meet again" does not survive a change of the wall's velocity.
    const std::uint32_t kind = last_[i] == kNone ? 0 : last_[i] >> 29;
    if (kind == static_cast<std::uint32_t>(Partner::moving_end) ||
        (kind == static_cast<std::uint32_t>(Partner::wall) && mover_of_[last_[i] & ((1u << 29) - 1)] != kNone))
      last_[i] = kNone;
    repredict(i);
  }
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
  } else if (!(straight(i) && last_[i] == last_code(Partner::wall, w))) {
    t_wall = now_ + toi_disc_segment(bi.x - p1, v, accel(i), s, bi.r);
  }
  if (t_wall < p.t_coll && t_wall <= horizon) {
    p.t_coll = t_wall;
    p.kind = Partner::wall;
    p.partner = w;
  }
  for (std::uint32_t which = 0; which < 2; ++which) {
    const std::uint32_t code = 2 * mi + which;
    if (straight(i) && last_[i] == last_code(Partner::moving_end, code)) continue;
    // Each end moves in a straight line, so its contacts have the closed forms of a fixed point.
    const Vec2 e = mover_end(m, which == 1, now_);
    const Vec2 ve = which == 0 ? v : v - m.w;  // the body's velocity relative to that end
    double dt;
    if (Flight::kAccelerates && !is_turtle(i)) dt = toi_disc_point_accel(bi.x - e, ve, flight_.a, bi.r, horizon - now_);
    else dt = toi_disc_point(bi.x - e, ve, bi.r);
    const double t = now_ + dt;
    if (t < p.t_coll && t <= horizon) {
      p.t_coll = t;
      p.kind = Partner::moving_end;
      p.partner = code;
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
  last_[i] = last_code(Partner::moving_end, code);
  repredict(i);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::add_end_layers(Vec2 p, const Layers& l) {
  // An end is there for a body if any wall that ends there is.
  for (std::size_t e = 0; e < ends_.size(); ++e)
    if (ends_[e].p == p) {
      end_layers_[e].category |= l.category;
      end_layers_[e].mask |= l.mask;
      return;
    }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
std::size_t Engine<Flight, kBallBall, kStep, kExtras>::add_wall(const WallDef& wall) {
  const Vec2 d = wall.to - wall.from;
  if (!(norm2(d) > 0.0) || !is_finite(wall.from) || !is_finite(wall.to))
    throw std::invalid_argument("wall '" + wall.id + "' has zero length or a non-finite end; give it two distinct ends");
  if (!wall.keys.empty() || !wall.visibility.empty())
    throw std::invalid_argument("wall '" + wall.id + "': a wall added while the world runs cannot move or come and go (keys, visibility); put it in the scene");
  if (boundary_ == Boundary::periodic)
    for (Vec2 p : {wall.from, wall.to})
      if (p.x < 0.0 || p.x > width_ || p.y < 0.0 || p.y > height_)
        throw std::invalid_argument("wall '" + wall.id + "' reaches outside a periodic arena; keep walls inside it");
  const Segment seg = make_segment(wall.from, wall.to);
  for (std::uint32_t i = 0; i < body_.size(); ++i) {
    const Body& b = body_[i];
    if (b.cell == kNone) continue;
    if constexpr (kExtras)
      if (!layers_[i].collides_with(wall.layers)) continue;  // it passes through this wall
    const Vec2 rel = rel_to_segment(pos_at(b, i, now_ - b.t), seg);
    const double foot = std::clamp(dot(rel, seg.u), 0.0, seg.len);
    const double gap = norm(rel - foot * seg.u) - b.r;
    if (gap < 0.0)
      throw std::invalid_argument("wall '" + wall.id + "' would overlap " + (is_turtle(i) ? "a turtle" : "a ball") +
                                  " (by " + std::to_string(-gap) + "); lay it clear of bodies");
  }
  // Append, so that the indices of walls and ends already named by predictions stay valid.
  const auto w = static_cast<std::uint32_t>(walls_.size());
  wall_defs_.push_back(wall);
  walls_.push_back(seg);
  for (Vec2 p : {wall.from, wall.to}) {
    const bool known = std::any_of(ends_.begin(), ends_.end(), [&](const WallEnd& e) { return e.p == p; });
    if (!known) {
      ends_.push_back({p, w});
      if constexpr (kExtras) end_layers_.push_back(Layers{0u, 0u});
    }
  }
  if constexpr (kExtras) {
    wall_layers_.push_back(wall.layers);
    base_mask_.push_back(wall.layers.mask);
    for (Vec2 p : {wall.from, wall.to}) add_end_layers(p, wall.layers);
  }
  mover_of_.push_back(kNone);
  std::vector<bool> moving(walls_.size());
  for (std::uint32_t k = 0; k < walls_.size(); ++k) moving[k] = mover_of_[k] != kNone;
  grid_ = CellGrid(width_, height_, cell_, grid_.periodic(), walls_, ends_, moving);  // same cells, new lists
  if constexpr (kStep) stamp_.assign(walls_.size() * 9 + ends_.size() * 9, 0);
  // Every prediction may now meet the new wall first.
  for (std::uint32_t i = 0; i < body_.size(); ++i) {
    if (body_[i].cell == kNone) continue;
    sync(i);
    repredict(i);
  }
  return w;
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

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::cross(std::uint32_t i) {
  ++stats_.cell_crossings;
  sync(i);
  Body& b = body_[i];
  const int dir = pending_[i].cross_dir;
  auto [ix, iy] = cell_xy(b.cell);
  ix += dir == 0 ? -1 : (dir == 1 ? 1 : 0);
  iy += dir == 2 ? -1 : (dir == 3 ? 1 : 0);
  if (ix < 1 || ix > grid_.nx() || iy < 1 || iy > grid_.ny()) {
    if (boundary_ != Boundary::periodic) {
      // The centre has left the arena. (With boundary walls this happens only if the walls were
      // missed; the body is removed rather than left to fly through the table.)
      const bool turtle = is_turtle(i);
      log(EventKind::exit, turtle ? i - nb_ : i, turtle ? 1 : 0);
      ++stats_.exits;
      remove(i);
      return;
    }
    if (ix < 1) { ix = grid_.nx(); b.x.x += width_; }
    else if (ix > grid_.nx()) { ix = 1; b.x.x -= width_; }
    if (iy < 1) { iy = grid_.ny(); b.x.y += height_; }
    else if (iy > grid_.ny()) { iy = 1; b.x.y -= height_; }
  }
  unlink(i);
  link(i, static_cast<std::uint32_t>(grid_.index(ix, iy)));
  predict_strip(i, dir, ix, iy);
  predict_crossing(i, ix, iy);
  schedule(i);
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::remove(std::uint32_t i) {
  unlink(i);
  body_[i].cell = kNone;
  ++body_[i].count;  // predictions made against it are now stale
  heap_.remove(i);
  if (is_turtle(i)) {
    busy_[i - nb_] = 0;
    end_[i] = kNever;
    body_[i].v = {};
  }
}

// ---------------------------------------------------------------------------------------------
// Time

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
double Engine<Flight, kBallBall, kStep, kExtras>::rebase() {
  // Keep internal times small: absolute times would lose a bit of position per doubling of t.
  // All bodies are brought to now, which becomes internal zero. Amortised O(1) per event.
  events_since_rebase_ = 0;
  const double shift = now_;
  if (shift == 0.0) return 0.0;
  for (std::uint32_t i = 0; i < body_.size(); ++i) {
    if (body_[i].cell == kNone) continue;
    sync(i);
    body_[i].t = 0.0;
    pending_[i].t_coll -= shift;
    pending_[i].t_cross -= shift;
    if (inelastic_) last_time_[i] -= shift;
  }
  for (std::size_t k = 0; k < run_.size(); ++k) {
    run_[k].t_start -= shift;
    end_[nb_ + k] -= shift;
  }
  for (Mover& m : movers_) m.t_ref -= shift;
  t_base_ += shift;
  refresh_next_key();
  now_ = 0.0;
  heap_.shift_keys(shift);
  return shift;
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::begin_step() {
  // Internal time zero is the start of the step; all bodies are there.
  const std::size_t n = body_.size();
  for (std::uint32_t i = 0; i < n; ++i) {
    if (body_[i].cell != kNone) unlink(i);
  }
  dmax_ = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) {
    Body& b = body_[i];
    if (b.cell == kNone) continue;
    b.t = 0.0;
    travel_[i] = 0.0;
    if (boundary_ == Boundary::periodic) {
      b.x.x -= width_ * std::floor(b.x.x / width_);
      b.x.y -= height_ * std::floor(b.x.y / height_);
    } else if (b.x.x < 0.0 || b.x.x > width_ || b.x.y < 0.0 || b.x.y > height_) {
      const bool turtle = is_turtle(i);
      log(EventKind::exit, turtle ? i - nb_ : i, turtle ? 1 : 0);
      ++stats_.exits;
      b.cell = kNone;
      ++b.count;
      heap_.remove(i);
      if (turtle) {
        busy_[i - nb_] = 0;
        end_[i] = kNever;
        b.v = {};
      }
      continue;
    }
    link(i, static_cast<std::uint32_t>(grid_.arena_cell_of(b.x)));
    dmax_ = std::max(dmax_, path_length(b.v, dt_));
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    if (body_[i].cell == kNone) continue;
    predict(i);
    schedule(i);
  }
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::finish_step() {
  now_ = dt_;
  for (std::uint32_t i = 0; i < body_.size(); ++i) {
    if (body_[i].cell == kNone) continue;
    sync(i);
    // The memo: fields act as velocity kicks between steps (not on turtles).
    if (!is_turtle(i)) body_[i].v += dt_ * kick_;
  }
  // A kick changes every course, so "just collided, cannot meet again" no longer holds.
  if (kick_.x != 0.0 || kick_.y != 0.0) for (std::uint32_t i = 0; i < last_.size(); ++i) last_[i] = kNone;
  ++step_index_;
  ++stats_.steps;
  ++stats_.events;
  for (std::size_t k = 0; k < run_.size(); ++k) {
    run_[k].t_start -= dt_;
    end_[nb_ + k] -= dt_;
  }
  for (Mover& m : movers_) m.t_ref -= dt_;
  if (inelastic_)
    for (double& t : last_time_) t -= dt_;
  t_base_ = static_cast<double>(step_index_) * dt_;
  refresh_next_key();
  now_ = 0.0;
  begin_step();
}

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
void Engine<Flight, kBallBall, kStep, kExtras>::advance_to(double t) {
  if (!(t >= time())) throw std::invalid_argument("advance_to: time " + std::to_string(t) + " is before the world's time");
  if constexpr (kStep) {
    for (;;) {
      const double target = t - t_base_;
      if (target >= dt_) {
        process(dt_);
        finish_step();
        continue;
      }
      process(target);
      now_ = std::max(now_, target);
      return;
    }
  } else {
    // The limit is always t - t_base_, rounded once. Shifting it along with a rebase would round
    // twice, and an event at the limit (a turtle's command that ends on a control step) would then
    // fall before or after the programs run there depending on where the run was cut into calls.
    while (!process(t - t_base_)) {
    }
    now_ = t - t_base_;
  }
}

// ---------------------------------------------------------------------------------------------
// Validate

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
  const reference::DiscView discs{n, pos, rad, alive};
  const bool periodic = boundary_ == Boundary::periodic;
  std::vector<Segment> walls_now = walls_;
  for (const Mover& m : movers_) walls_now[m.wall] = mover_segment(m, now_);
  if (!kBallBall && nb_ > 0) {
    // Balls pass through each other by request: measure walls for everyone, and pairs among the
    // turtles and between turtles and balls.
    Overlap worst = reference::overlap(discs, walls_now, periodic ? width_ : 0.0, periodic ? height_ : 0.0, false,
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
  return reference::overlap(discs, walls_now, periodic ? width_ : 0.0, periodic ? height_ : 0.0, true,
                            kExtras ? &layers_ : nullptr, kExtras ? &wall_layers_ : nullptr);
}

template <class Flight, bool kBallBall, bool kExtras>
std::unique_ptr<EngineBase> make_for_mode(const WorldDef& def, Mode mode, std::vector<BallDef>* release) {
  if (mode == Mode::step) return std::make_unique<Engine<FreeFlight, kBallBall, true, kExtras>>(def, release);
  return std::make_unique<Engine<Flight, kBallBall, false, kExtras>>(def, release);
}

template <class Flight, bool kBallBall>
std::unique_ptr<EngineBase> make_with_extras(const WorldDef& def, Mode mode, std::vector<BallDef>* release) {
  const Layers plain{};
  bool layered = false;
  for (const auto& b : def.balls) layered = layered || !(b.layers == plain);
  for (const auto& t : def.turtles) layered = layered || !(t.layers == plain);
  for (const auto& w : def.walls) layered = layered || !(w.layers == plain) || !w.keys.empty() || !w.visibility.empty();
  if (def.turtles.empty() && !layered) return make_for_mode<Flight, kBallBall, false>(def, mode, release);
  return make_for_mode<Flight, kBallBall, true>(def, mode, release);
}

std::unique_ptr<EngineBase> make(const WorldDef& def, Mode mode, std::vector<BallDef>* release) {
  // The physics is chosen here, once per scene: one instantiation per combination of effects.
  const bool gravity = def.effects.gravity.x != 0.0 || def.effects.gravity.y != 0.0;
  const bool ball_ball = def.effects.ball_ball;
  if (gravity) {
    return ball_ball ? make_with_extras<GravityFlight, true>(def, mode, release)
                     : make_with_extras<GravityFlight, false>(def, mode, release);
  }
  return ball_ball ? make_with_extras<FreeFlight, true>(def, mode, release)
                   : make_with_extras<FreeFlight, false>(def, mode, release);
}

}  // namespace

std::unique_ptr<EngineBase> make_engine(const WorldDef& def, Mode mode) { return make(def, mode, nullptr); }

std::unique_ptr<EngineBase> make_engine(WorldDef&& def, Mode mode) { return make(def, mode, &def.balls); }

}  // namespace turtlegas::sim::detail
