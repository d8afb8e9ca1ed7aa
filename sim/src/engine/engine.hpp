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
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>

#include "../cell_grid.hpp"
#include "../event_queue.hpp"
#include "cell_size.hpp"
#include "engine_base.hpp"
#include "flights.hpp"
#include "moving_walls.hpp"
#include "records.hpp"
#include "turtle_motion.hpp"
#include "turtlegas/sim/toi.hpp"
#include "variant.hpp"

namespace turtlegas::sim::detail {
namespace {

double path_length(Vec2 v, double dt) { return norm(v) * dt; }

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
  Column<LastPartner, last_of> last_;
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
  for (const auto& b : def.balls) rmax_ = std::max(rmax_, b.radius);
  for (const auto& t : def.turtles) rmax_ = std::max(rmax_, t.radius);
  const double cell = choose_cell_size(def, kStep ? Mode::step : Mode::exact);
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
void Engine<Flight, kBallBall, kStep, kExtras>::after_change(std::uint32_t i) {
  ++body_[i].count;
  if (inelastic_) last_time_[i] = now_;
  if constexpr (kStep) {
    // The rest of the step is walked at the new speed.
    dmax_ = std::max(dmax_, travel_[i] + path_length(body_[i].v, dt_ - now_));
  }
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


}  // namespace
}  // namespace turtlegas::sim::detail

#include "added_walls.hpp"
#include "checks.hpp"
#include "exact_clock.hpp"
#include "interactions.hpp"
#include "neighbourhood.hpp"
#include "step_clock.hpp"
#include "turtle_commands.hpp"
#include "wall_schedule.hpp"

namespace turtlegas::sim::detail {

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
std::unique_ptr<EngineBase> make_variant(const WorldDef& def, std::vector<BallDef>* release) {
  return std::make_unique<Engine<Flight, kBallBall, kStep, kExtras>>(def, release);
}

}  // namespace turtlegas::sim::detail

/// The explicit instantiation of one row of the table in factory.cpp (see variant.hpp).
#define TURTLEGAS_ENGINE_VARIANT(flight, balls, mode, extras)                                   \
  namespace turtlegas::sim::detail {                                                             \
  template std::unique_ptr<EngineBase> make_variant<flight, variant::balls, variant::mode, variant::extras>( \
      const WorldDef&, std::vector<BallDef>*);                                                   \
  }
