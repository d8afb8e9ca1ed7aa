// SPDX-License-Identifier: MIT
//
// (Just over 600 lines: the class's declaration is the one place that lists every room it holds
// and every operation a World forwards to it; the operations' bodies live in the files it names.)
//
// The GAS engine. One class template, instantiated once per row of the table of variants
// (factory.cpp): the flight (straight, or parabolas under gravity), ball-ball collisions on or
// off, exact or step mode, extras or not. It is chosen when the World is built, so nothing is
// decided per collision. The engine owns the loop and the two clocks; the rooms it holds do the
// rest, each receiving what it touches (room_views.hpp). `ls sim/src/engine` reads:
//   engine_base.hpp            EngineBase, the interface World forwards to; make_engine
//   factory.cpp                the table of compiled variants, and the choice of a row
//   variant_seam.hpp           make_variant: the seam between the table and the units compiling it
//   records.hpp, body_store.*  the bodies: one 128-byte record each, columns, cell lists
//   big_memory.*               the records' and the cell lists' memory (huge pages when large)
//   arena.hpp                  the arena's size and boundary, minimum images
//   flights.hpp                how balls fly, and the time-of-impact choice that follows
//   charged_flight.cpp         ChargedFlight's out-of-line parts (balls under E and B fields)
//   kick.hpp                   step mode's field, a velocity kick between steps
//   room_views.hpp             what the rooms see of each other: Look (a prediction), Parts (a response)
//   neighbourhood.hpp          who a body looks at (the memo's table, CellGrid)
//   interactions.hpp           predict / apply / validate per pair kind
//   contacts/                  zero-time contacts, the principle on top (contacts.hpp): tolerances,
//                              skip(), squeeze.hpp (wedged or crushed), carried.hpp (turtles a
//                              moving wall pushes), restitution.hpp (the TC rule), resolve.hpp
//                              (the hook after a contact: collide)
//   turtle_motion.*            turtles' commands, contacts and state
//   walls.*, moving_walls.*    walls and their ends; keyframes and visibility
//   cell_size.*, checks.hpp    the cell-size policy; energy and overlap
//   exact_clock.hpp            cell crossings, exits, the rebase of internal time
//   step_clock.hpp             the start and the end of one of the memo's steps
//   saved_state.hpp            the engine's whole memory as plain data, and back (checkpoints)
//   world_changes.hpp          spawn, remove, teleport: changes to a running world
//   region.hpp                 the balls in a rectangle, from the cell lists
//   rays.hpp                   ray casts (range sensors): the grid walked along a ray
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
//   3. Move every ball to the end of the step and apply the field kick (kick.hpp: v += a dt).
//      Balls outside an open arena exit; a periodic arena wraps them.
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
#include <bit>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "../cell_grid.hpp"
#include "../event_queue.hpp"
#include "turtlegas/sim/control_steps.hpp"
#include "arena.hpp"
#include "body_store.hpp"
#include "cell_size.hpp"
#include "checks.hpp"
#include "contacts/carried.hpp"
#include "contacts/contacts.hpp"
#include "contacts/squeeze.hpp"
#include "engine_base.hpp"
#include "flights.hpp"
#include "interactions.hpp"
#include "kick.hpp"
#include "moving_walls.hpp"
#include "neighbourhood.hpp"
#include "records.hpp"
#include "room_views.hpp"
#include "turtle_motion.hpp"
#include "variant_seam.hpp"
#include "walls.hpp"

namespace turtlegas::sim::detail {
namespace {

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
class Engine final : public EngineBase {
  // Step mode flies straight and kicks between steps: its field is a run-time Kick, never a flight.
  static_assert(!kStep || std::same_as<F, FreeFlight>, "step mode flies straight (FreeFlight)");

 public:
  /// Builds the engine for `def`. `release`, when given, is def's own ball list: it is emptied and
  /// its memory freed as soon as the balls have been copied, before the rest of the engine is
  /// allocated, so that the scene and the whole engine never take memory at the same time.
  Engine(const WorldDef& def, std::vector<BallDef>* release);

  void advance_to(double t) override;
  void set_event_log(std::vector<Event>* log) override { record_.log = log; }
  std::unique_ptr<EngineBase> clone() const override {
    // Every room is a value (vectors, the cell lists, the clocks and counters) but for the
    // records, which BodyStore's copy gives a place of their own, and the queue, whose nodes
    // live in the records: it is rebound to the copy's. The log pointers are the caller's.
    auto copy = std::make_unique<Engine>(*this);
    copy->heap_.rebind(copy->bodies_.nodes());
    copy->record_.log = nullptr;
    copy->record_.impulses = nullptr;
    copy->stop_poll_ = nullptr;  // the caller's, like the logs
    copy->arm_check();
    return copy;
  }
  // A saved state (saved_state.hpp).
  bool can_save_state() const override { return !kExtras; }
  EngineState save_state() const override;
  void restore_state(const EngineState& state) override;
  void set_impulse_log(std::vector<Impulse>* log) override { record_.impulses = log; }
  void set_event_limit(std::uint64_t limit) override {
    event_limit_ = limit;
    arm_check();
  }
  void set_stop_poll(std::function<bool()> poll, std::uint64_t every) override {
    stop_poll_ = std::move(poll);
    poll_every_ = std::max<std::uint64_t>(every, 1);
    arm_check();
  }
  double time() const override { return t_base_ + now_; }
  std::size_t ball_count() const override { return bodies_.balls(); }
  BallState ball(std::size_t i) const override {
    const Body& b = bodies_.body[i];
    const double dt = now_ - b.t;
    const auto id = static_cast<std::uint32_t>(i);
    return {motion_.flight().pos(id, b.x, b.v, dt), motion_.flight().vel(id, b.v, dt), b.cell != kNone};
  }
  double radius(std::size_t i) const override { return bodies_.body[i].r; }
  double mass(std::size_t i) const override { return bodies_.mass[i]; }
  const std::vector<WallDef>& walls() const override { return walls_.defs; }
  std::size_t turtle_count() const override { return turtles_.size(); }
  TurtleState turtle(std::size_t k) const override {
    const std::size_t id = bodies_.balls() + k;
    TurtleState s = turtles_.state(k, bodies_.body[id], bodies_.end[id], now_);
    if (motion_.any_arcs()) [[unlikely]] {
      const Body& b = bodies_.body[id];
      const FieldState f = motion_.state(b, static_cast<std::uint32_t>(id), now_ - b.t);
      s.pos = f.x;
      s.vel = f.v;
    }
    return s;
  }
  double turtle_radius(std::size_t k) const override { return bodies_.body[bodies_.balls() + k].r; }
  void idle_turtles(std::vector<std::uint32_t>& out) const override { turtles_.idle(out); }
  void prefetch_turtle(std::size_t k) const override {
    // What turtle(k) and command_turtle(k) read first: the turtle's record (two lines) and its
    // command state (which may straddle two).
    if (k >= turtles_.size()) return;
    const char* rec = reinterpret_cast<const char*>(&bodies_.body[bodies_.balls() + k]);
    __builtin_prefetch(rec);
    __builtin_prefetch(rec + 64);
    const char* run = reinterpret_cast<const char*>(&turtles_.run(k));
    __builtin_prefetch(run);
    __builtin_prefetch(run + sizeof(TurtleRun) - 1);
  }
  void command_turtle(std::size_t k, const TurtleCommand& command) override;
  std::size_t add_wall(const WallDef& wall) override;
  // Changes to a running world (world_changes.hpp).
  std::size_t spawn_ball(const BallDef& ball) override;
  std::size_t spawn_turtle(const TurtleDef& turtle) override;
  void remove_body(bool turtle, std::size_t index) override;
  void teleport_ball(std::size_t i, Vec2 pos, Vec2 vel) override;
  void teleport_turtle(std::size_t i, Vec2 pos, double heading) override;
  void balls_in_rect(Vec2 lo, Vec2 hi, std::vector<std::uint32_t>& out) const override;  // region.hpp
  RayHit cast_ray(const Ray& ray) const override;  // rays.hpp
  void cast_rays(const Ray& ray, const Vec2* dirs, std::size_t n, RayHit* out) const override;  // rays.hpp
  bool turtle_alive(std::size_t k) const override {
    return k < turtles_.size() && bodies_.body[bodies_.balls() + k].cell != kNone;
  }
  std::vector<TurtleContact> take_turtle_contacts() override { return turtles_.take_contacts(); }
  double energy() const override {
    if constexpr (kStep) return detail::energy(look(), kick_);
    else return detail::energy(look(), motion_.flight());
  }
  const Stats& stats() const override { return record_.stats; }
  const std::vector<double>& energy_taken() const override { return record_.taken; }
  Overlap measure_overlap() const override {
    return detail::measure_overlap<kBallBall>(look(), arena_, overlap_scratch_);
  }
  Overlap max_contact_overlap() const override { return record_.max_contact; }
  double cell_size() const override { return std::min(grid_.cell_w(), grid_.cell_h()); }
  int cells_x() const override { return grid_.nx(); }
  int cells_y() const override { return grid_.ny(); }
  Mode mode() const override { return kStep ? Mode::step : Mode::exact; }
  double dt() const override { return dt_; }

 private:
  bool is_turtle(std::uint32_t id) const { return motion_.is_turtle(id); }
  Look<F, kExtras> look() const { return {bodies_, walls_, schedule_, motion_, now_}; }
  Parts<F, kStep, kExtras> parts() {
    return {bodies_, motion_, walls_, schedule_, turtles_, arena_, restitution_, step_, record_, now_, t_base_, dt_};
  }
  void sync(std::uint32_t i) { sync_body<F, kStep, kExtras>(bodies_, motion_, step_, i, now_); }
  void link(std::uint32_t i, std::uint32_t cell) { bodies_.link(i, cell, is_turtle(i)); }
  void unlink(std::uint32_t i) { bodies_.unlink(i, is_turtle(i)); }

  struct CellXY {
    int ix, iy;
  };
  /// Column and row of a cell (one integer division).
  CellXY cell_xy(std::uint32_t cell) const {
    const int c = static_cast<int>(cell), stride = grid_.stride();
    const int iy = c / stride;
    return {c - iy * stride, iy};
  }

  // Predict: body i's earliest collision (neighbourhood.hpp chooses the candidates), and in exact
  // mode the time it leaves its cell. (ix, iy): the body's cell, where the caller has it.
  void predict(std::uint32_t i) {
    const CellXY c = cell_xy(bodies_.body[i].cell);
    predict(i, c.ix, c.iy);
  }
  void predict(std::uint32_t i, int ix, int iy);
  void predict_crossing(std::uint32_t i) {
    const CellXY c = cell_xy(bodies_.body[i].cell);
    predict_crossing(i, c.ix, c.iy);
  }
  void predict_crossing(std::uint32_t i, int ix, int iy);
  /// The internal time of control boundary j (internal_boundary: in step mode the step's end is dt).
  double boundary_end(std::uint64_t j) const { return internal_boundary(j, t_base_, dt_, kStep, step_.index); }
  /// Internal time has moved by -shift (t_base_ already moved): the turtles' command ends follow,
  /// those on a control boundary recomputed from it rather than shifted (two roundings).
  void shift_turtle_ends(double shift) {
    const std::size_t nb = bodies_.balls();
    for (std::size_t k = 0; k < turtles_.size(); ++k) {
      const std::uint64_t j = turtles_.end_step[k];
      double& end = bodies_.end[nb + k];
      end = j == kNoStep ? end - shift : boundary_end(j);
    }
  }
  /// When a turtle's command ends (kNever for a ball, or a turtle with no command running).
  double command_end(std::uint32_t i) const {
    if constexpr (kExtras) return is_turtle(i) ? bodies_.end[i] : kNever;
    else return kNever;
  }
  void schedule(std::uint32_t i) {
    const Pending& p = bodies_.pending[i];
    heap_.set(i, std::min(std::min(p.t_coll, p.t_cross), command_end(i)));
  }
  void repredict(std::uint32_t i) {
    const CellXY c = cell_xy(bodies_.body[i].cell);
    if constexpr (F::kBoundedHorizon) {
      predict_crossing(i, c.ix, c.iy);  // first: it is the prediction's horizon
      predict(i, c.ix, c.iy);
    } else {
      predict(i, c.ix, c.iy);
      if constexpr (!kStep) predict_crossing(i, c.ix, c.iy);  // crossing times depend on the velocity just changed
    }
    schedule(i);
  }
  /// Body i's course changed outside a collision (a command, a push): predictions made with it
  /// are stale, and "just collided, cannot meet again" no longer holds.
  void new_course(std::uint32_t i) {
    ++bodies_.body[i].count;
    bodies_.last[i] = LastPartner::none();
    if constexpr (kStep)
      step_.dmax = std::max(step_.dmax, step_.travel[i] + path_length(bodies_.body[i].v, dt_ - now_));
    repredict(i);
  }

  // Serve: the loop and what it dispatches to.
  /// Serves events up to internal time `limit`. Returns false when it stopped early to rebase the
  /// clock (exact mode), so that the caller takes the limit afresh in the new internal time.
  bool process(double limit);
  /// Serves body i's predicted contact, and the squeeze rule after it (contacts/resolve.hpp).
  void collide(std::uint32_t i);
  void served(Changed c) {
    repredict(c.first);
    if (c.second != kNone) repredict(c.second);
  }
  void end_command(std::uint32_t i);
  void keyframe();
  // world_changes.hpp
  /// Throws PlacementError unless a disc of radius r at pos (layers `layers`) lies clear of the
  /// walls and of every body but `self` (kNone: none), inside the arena.
  void check_clear(Vec2 pos, double r, const Layers& layers, std::uint32_t self) const;
  /// Makes id `at` for a new body (BodyStore::insert) and everything kept per body with it.
  void make_room(std::uint32_t at, bool ball, const Layers& layers);
  /// Body i, brought to now and placed at pos (unlinked already, or new), enters its cell and
  /// predicts afresh.
  void place(std::uint32_t i, Vec2 pos);
  /// The sliding flight (docs/physics.md, "The sliding flight"): only a GravityFlight's balls
  /// slide, so only exact mode under gravity pays for it.
  static constexpr bool kSlides = requires(F f, std::uint32_t i) { f.end_slide(i); };
  /// Ball i lands on fixed wall w, having met `before` last: whether the bounces that would follow
  /// form a Zeno sequence short enough to be its limit, the slide, which it then starts
  /// (contacts/resolve.hpp). False: an ordinary bounce.
  bool slide_landing(std::uint32_t i, std::uint32_t w, LastPartner before);
  /// Something strikes body i, or it strikes something: if it slides, it is a disc again (brought
  /// to now first; the response that follows bumps its counter).
  void unslide(std::uint32_t i) {
    if constexpr (kSlides) {
      if (motion_.flight().sliding(i)) [[unlikely]] {
        sync(i);
        motion_.flight().end_slide(i);
      }
    }
  }
  /// The jammed chain (docs/physics.md, "Clusters: a jammed chain"): ball i has just met a standing
  /// `obstacle` (a fixed wall or wall end, a turtle) after ball `before`; if it heads a straight
  /// row of touching balls that ends on another standing obstacle in line, and nothing else
  /// touches the row but across it or out of its reach, every ball's velocity along the row is
  /// taken (the limit of the zero-time sequence), and true is returned (contacts/resolve.hpp). Out of line: it runs only
  /// after a ball, and inlined it would change GCC's inlining of the engine's loop.
  [[gnu::noinline]] bool jammed_chain(std::uint32_t i, LastPartner obstacle, LastPartner before);
  /// The squeeze rule (contacts/squeeze.hpp) for body i after its contact with bodies_.last[i]; `before`:
  /// its partner before that. Returns false when the body was crushed (and removed).
  bool squeezed(std::uint32_t i, LastPartner before);
  /// Body i is crushed between A and B: it is removed, with a `crushed` event.
  void crush(std::uint32_t i, const Side& A, const Side& B);
  /// Body i, taken out of its cell list (unlink), leaves the world (crushed or exited): out of
  /// the queue, predictions made against it stale, a turtle's command ended. Its record stays,
  /// with cell kNone. (remove_body writes the same steps out: calling this from
  /// there too changed GCC's inlining of the engine's loop, +0.14 % of the gas's instructions.)
  void retire(std::uint32_t i);

  // The exact clock (exact_clock.hpp).
  /// Inlined into process(), its one caller: robust3's additions to process() made GCC call it
  /// out of line, +1.5 % instructions per event on the uncharged gas (callgrind, docs/performance.md).
  [[gnu::always_inline]] void cross(std::uint32_t i);
  /// Body i's centre has left an open arena: it is removed (retire), with an `exit` event.
  void exit(std::uint32_t i);
  double rebase();

  // The step clock (step_clock.hpp).
  void begin_step();
  void finish_step();

  Motion<F, kExtras> motion_;
  Kick kick_;  ///< step mode's field
  Restitution restitution_;
  Arena arena_;
  double dt_ = 0.0;

  BodyStore bodies_;
  Walls walls_;
  WallSchedule schedule_;
  Turtles turtles_;
  CellGrid grid_;
  double cell_ = 0.0;  ///< the cell side the grid was built for (rebuilt with it when walls are added)
  EventQueue heap_;

  double now_ = 0.0;     ///< internal time, relative to t_base_
  double t_base_ = 0.0;  ///< external time of internal time zero
  std::uint64_t events_since_rebase_ = 0;
  std::uint64_t rebase_every_ = 0;
  std::uint64_t event_limit_ = ~std::uint64_t{0};  ///< World::set_event_limit
  std::function<bool()> stop_poll_;                 ///< World::set_stop_poll
  std::uint64_t poll_every_ = 1;
  /// The event count at which process() next looks at the limit and the poll: the one compare
  /// per event that the limit alone used to cost, so a poll adds nothing to the loop itself.
  std::uint64_t next_check_ = ~std::uint64_t{0};
  void arm_check() {
    next_check_ = stop_poll_ ? std::min(event_limit_, record_.stats.events + poll_every_) : event_limit_;
  }
  /// At next_check_: throws EventLimitReached or StopRequested, or sets the next check.
  [[gnu::cold, gnu::noinline]] void check_stop();
  StepState step_;  ///< step mode only
  /// The jammed chain's states seen at one instant where a contact at an angle kept the rule out:
  /// the velocities and last partners of the row and of what touches it at an angle, to see the
  /// zero-time sequence come back to one of them (contacts/resolve.hpp). Empty but at such an
  /// instant.
  struct RowsSeen {
    double t = 0.0;
    std::vector<std::vector<std::uint64_t>> states;
  } rows_seen_;

  EventRecord record_;
  /// The overlap measure's buffers (measure_overlap), kept so that a run measuring at many instants
  /// allocates once; a measure writes them, so it is no more for concurrent use than the rest.
  mutable OverlapScratch overlap_scratch_;
};

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
Engine<F, kBallBall, kStep, kExtras>::Engine(const WorldDef& def, std::vector<BallDef>* release) {
  if (auto problem = validate(def)) throw std::invalid_argument(problem->message);
  const EffectsDef& fx = def.effects;
  motion_ = Motion<F, kExtras>(def);
  if constexpr (kStep) kick_ = Kick(def);
  restitution_.e = fx.restitution;
  restitution_.tc = fx.tc;
  restitution_.inelastic = fx.restitution < 1.0;
  arena_ = {def.arena.width, def.arena.height, def.arena.boundary};
  dt_ = def.dt;

  walls_ = Walls(def, kExtras);
  schedule_ = WallSchedule(walls_);
  for (const auto& b : def.balls) step_.rmax = std::max(step_.rmax, b.radius);
  for (const auto& t : def.turtles) step_.rmax = std::max(step_.rmax, t.radius);
  cell_ = choose_cell_size(def, kStep ? Mode::step : Mode::exact);
  bodies_ = BodyStore(def, release, kExtras);
  turtles_ = Turtles(def.turtles);
  const std::size_t n = bodies_.size();

  grid_ = CellGrid(arena_.width, arena_.height, cell_, arena_.periodic(), walls_.segments, walls_.ends, walls_.moving());
  if (arena_.periodic() && (grid_.nx() < 3 || grid_.ny() < 3)) {
    if (kStep && !def.arena.cell) {
      // The cell is the memo's rule 2 (r_max + v_max dt): name what made it too wide.
      double vmax = 0.0;
      for (std::uint32_t i = 0; i < n; ++i) vmax = std::max(vmax, norm(bodies_.body[i].v));
      throw std::invalid_argument("step mode: the fastest body's speed " + format_number(vmax) + " at dt = " +
                                  format_number(dt_) + " makes the cell rule 2 (r_max + v_max dt) = " +
                                  format_number(cell_) + ", more than a third of this periodic arena (" +
                                  format_number(arena_.width) + " x " + format_number(arena_.height) +
                                  "): use a smaller dt or --mode exact");
    }
    throw std::invalid_argument("a periodic arena must be at least 3 cells across (cell " + std::to_string(cell_) +
                                "); enlarge the arena or use smaller balls");
  }

  if (restitution_.inelastic) restitution_.last_time.assign(n, -kNever);
  bodies_.make_lists(static_cast<std::size_t>(grid_.cell_count()), kExtras);
  heap_.reset(bodies_.nodes(), sizeof(Record), n);
  if constexpr (kStep) {
    step_.travel.assign(n, 0.0);
    step_.stamp.assign(walls_.segments.size() * 9 + walls_.ends.size() * 9, 0);
  }
  // Balls, then turtles, each in list order, as the cell lists have always been built.
  for (std::uint32_t i = 0; i < n; ++i) link(i, static_cast<std::uint32_t>(grid_.arena_cell_of(bodies_.body[i].x)));
  if constexpr (kExtras) {
    schedule_.apply_visibility(walls_, now_, t_base_);
    turtles_.pushed_by.assign(turtles_.size(), kNone);
    turtles_.pushed_via.assign(turtles_.size(), kNone);
    schedule_.aim_all(walls_, t_base_);
  }
  rebase_every_ = std::max<std::uint64_t>(4 * n, 4096);
  if constexpr (kStep) {
    begin_step();
  } else {
    for (std::uint32_t i = 0; i < n; ++i) {
      if constexpr (F::kBoundedHorizon) {
        predict_crossing(i);
        predict(i);
      } else {
        predict(i);
        predict_crossing(i);
      }
      schedule(i);
    }
  }
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::predict(std::uint32_t i, int ix, int iy) {
  const Body& bi = bodies_.body[i];
  Pending& p = bodies_.pending[i];
  // A turtle's command end is not a candidate here: it is kept apart (command_end()), so that a
  // turtle whose command starts or ends without moving it keeps the collisions predicted for it.
  p.t_coll = kNever;
  p.kind = Partner::none;
  if constexpr (F::kBoundedHorizon) {
    // Curved flights look no further than the cell exit (or the flight's re-plan time), when the
    // body predicts afresh anyway: the bracketed searches need a finite horizon, and every search
    // is cheaper for it. Nothing found leaves no candidate.
    if (!motion_.flight().closed_forms()) p.t_coll = p.t_cross;
    look_around<kBallBall>(look(), grid_, i, bi, ix, iy, p);
    if (p.kind == Partner::none) p.t_coll = kNever;
  } else if constexpr (!kStep) {
    look_around<kBallBall>(look(), grid_, i, bi, ix, iy, p);
  } else {
    look_along_step<kBallBall>(look(), grid_, step_, dt_, i, bi, ix, iy, p);
  }
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::predict_crossing(std::uint32_t i, int ix, int iy) {
  const Body& b = bodies_.body[i];
  Pending& p = bodies_.pending[i];
  const CellExit e = motion_.cell_exit(i, b.x, b.v, cell_box(grid_, ix, iy));
  p.t_cross = now_ + e.t;
  p.cross_dir = e.dir;
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
bool Engine<F, kBallBall, kStep, kExtras>::process(double limit) {
  for (;;) {
    const double next_event = heap_.empty() ? kNever : heap_.top_key();
    if constexpr (kExtras) {
      // A moving wall reaching a keyframe changes course: everything predicts again.
      if (schedule_.next_key <= limit && schedule_.next_key <= next_event) {
        keyframe();
        continue;
      }
    }
    if (next_event > limit) break;
    if (record_.stats.events >= next_check_) [[unlikely]] check_stop();
    const std::uint32_t i = heap_.top_id();
    now_ = heap_.top_key();
    ++record_.stats.events;
    // The next events most likely belong to the top's children in the served bucket (or to the
    // next bucket): start loading their state now, which hides a cache miss or two per event once
    // the bodies outgrow the cache. (Written out rather than through a callback: GCC 12 drops the
    // prefetches of a lambda that does nothing else.)
    for (std::size_t n = 0; n < 2; ++n) {
      const std::uint32_t k = heap_.next_id(n);
      if (k == EventQueue::kAbsent) continue;
      __builtin_prefetch(&bodies_.body[k]);
      __builtin_prefetch(&bodies_.pending[k]);
    }
    const Pending& p = bodies_.pending[i];
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

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::check_stop() {
  if (record_.stats.events >= event_limit_)
    throw EventLimitReached("the event limit (" + std::to_string(event_limit_) + ") was reached at t = " +
                            std::to_string(t_base_ + now_));
  if (stop_poll_ && stop_poll_()) throw StopRequested("stopped by the poll at t = " + std::to_string(t_base_ + now_));
  arm_check();
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::crush(std::uint32_t i, const Side& A, const Side& B) {
  const bool turtle = is_turtle(i);
  const std::uint32_t nb = bodies_.balls();
  record_.note(t_base_ + now_, EventKind::crushed, turtle ? i - nb : i, A.name, B.name,
               squeeze_flags(turtle, A, B));
  ++record_.stats.crushed;
  if (!turtle) {  // the ledger: a ball leaves with its energy (checks.hpp's, as energy() counts it)
    if constexpr (kStep) record_.take_energy(record_.stats.energy_crushed, i, ball_energy(look(), kick_, i));
    else record_.take_energy(record_.stats.energy_crushed, i, ball_energy(look(), motion_.flight(), i));
  }
  unlink(i);
  retire(i);
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::retire(std::uint32_t i) {
  Body& b = bodies_.body[i];
  b.cell = kNone;
  ++b.count;  // predictions made against it are now stale
  heap_.remove(i);
  if constexpr (kSlides) motion_.flight().end_slide(i);
  if (is_turtle(i)) {
    turtles_.exit(i - bodies_.balls(), b, bodies_.end[i]);
    motion_.set_arc(i - bodies_.balls(), 0.0);
  }
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::end_command(std::uint32_t i) {
  // A turtle's command (or its coasting after a bounce) has run its course.
  sync(i);
  const std::size_t k = i - bodies_.balls();
  if (Vec2 end; turtles_.arc_end(k, end)) [[unlikely]] {
    // An arc run to its end ends at its closed form (Turtles::arc_end), not at the sum of the
    // round-offs of the events it passed: the two differ by round-off only (a lap ends where it
    // began, exactly). In a periodic arena the body may be an image away.
    Body& b = bodies_.body[i];
    const Vec2 d = arena_.min_image(end - b.x);
    if (norm(d) <= 1e-9 * (b.r + norm(turtles_.run(k).v0) * dt_)) b.x = b.x + d;
  }
  motion_.set_arc(k, 0.0);
  if (!turtles_.finish(k, bodies_.body[i], bodies_.end[i])) {
    // The disc stood still and stays still: only its key loses the command's end.
    schedule(i);
    return;
  }
  parts().changed(i);
  bodies_.last[i] = LastPartner::none();
  repredict(i);
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::command_turtle(std::size_t k, const TurtleCommand& c) {
  if (k >= turtles_.size()) throw std::out_of_range("command_turtle: no turtle " + std::to_string(k));
  const auto id = static_cast<std::uint32_t>(bodies_.balls() + k);
  if (bodies_.body[id].cell == kNone) return;  // it has left the arena
  if (c.kind == TurtleCommand::Kind::arc && c.rate != 0.0) {
    // There is no exact solver for a circle against a turning or stretching wall (ChargedFlight's
    // circles are refused there too, validate.cpp).
    for (const Mover& m : schedule_.movers)
      if (!m.rigid())
        throw std::invalid_argument("turtle #" + std::to_string(k) +
                                    ": arcs are not simulated while a wall turns or stretches (no exact solver); "
                                    "drive straight strokes and turns in this world");
  }
  sync(id);
  const bool moved = turtles_.command(k, c, bodies_.body[id], bodies_.end[id], now_);
  motion_.set_arc(k, turtles_.busy(k) && c.kind == TurtleCommand::Kind::arc ? c.rate : 0.0);
  if constexpr (kExtras) {
    // A command lasting a whole number of control steps ends on that boundary, exactly.
    if (const std::uint64_t j = turtles_.snap_end(k, bodies_.end[id], t_base_, dt_); j != kNoStep)
      bodies_.end[id] = boundary_end(j);
  }
  if (!moved) {
    // The predictions made with it still hold; only its key takes the command's end.
    schedule(id);
    return;
  }
  new_course(id);
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::keyframe() {
  now_ = schedule_.next_key;
  ++record_.stats.events;
  schedule_.take_keyframe(walls_, now_, t_base_);
  bodies_.release_held();  // a wall may have changed course: the squeeze rule's marks no longer hold
  const std::uint32_t nb = bodies_.balls();
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    Body& b = bodies_.body[i];
    if (b.cell == kNone) continue;
    sync(i);
    if constexpr (kSlides) {
      // A slide is the limit of bounces off a wall that stays put: a keyframe (which may hide that
      // wall) ends it; it starts again at its next landing if the wall is still there.
      if (motion_.flight().sliding(i)) {
        motion_.flight().end_slide(i);
        ++b.count;
      }
    }
    if (is_turtle(i)) push_ends(turtles_, i - nb, b, schedule_.keyed);  // contacts/carried.hpp
    if (keyed_partner(bodies_.last[i], walls_, schedule_)) bodies_.last[i] = LastPartner::none();  // contacts.hpp
    repredict(i);
  }
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
std::size_t Engine<F, kBallBall, kStep, kExtras>::add_wall(const WallDef& wall) {
  walls_.check_new(wall, arena_.def());
  const Segment seg = make_segment(wall.from, wall.to);
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    const Body& b = bodies_.body[i];
    if (b.cell == kNone) continue;
    if constexpr (kExtras)
      if (!bodies_.layers[i].collides_with(wall.layers)) continue;  // it passes through this wall
    const Vec2 rel = arena_.rel_to_segment(motion_.pos(b, i, now_ - b.t), seg);
    const double foot = std::clamp(dot(rel, seg.u), 0.0, seg.len);
    const double gap = norm(rel - foot * seg.u) - b.r;
    if (gap < 0.0)
      throw std::invalid_argument("wall '" + wall.id + "' would overlap " + (is_turtle(i) ? "a turtle" : "a ball") +
                                  " (by " + std::to_string(-gap) + "); lay it clear of bodies");
  }
  const std::uint32_t w = walls_.add(wall, kExtras);
  grid_ = CellGrid(arena_.width, arena_.height, cell_, grid_.periodic(), walls_.segments, walls_.ends,
                   walls_.moving());  // same cells, new lists
  if constexpr (kStep) step_.stamp.assign(walls_.segments.size() * 9 + walls_.ends.size() * 9, 0);
  // Every prediction may now meet the new wall first.
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_.body[i].cell == kNone) continue;
    sync(i);
    repredict(i);
  }
  return w;
}

template <Flight F, bool kBallBall, bool kStep, bool kExtras>
void Engine<F, kBallBall, kStep, kExtras>::advance_to(double t) {
  if (!(t >= time())) throw std::invalid_argument("advance_to: time " + std::to_string(t) + " is before the world's time");
  if constexpr (kStep) {
    for (;;) {
      const double target = t - t_base_;
      // A t on the step's closing boundary closes the step, though t - t_base_ may round below dt.
      if (target >= dt_ || t >= control_boundary(step_.index + 1, dt_)) {
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

#include "contacts/resolve.hpp"
#include "exact_clock.hpp"
#include "world_changes.hpp"
#include "region.hpp"
#include "rays.hpp"
#include "step_clock.hpp"
#include "saved_state.hpp"

namespace turtlegas::sim::detail {

template <class Flight, bool kBallBall, bool kStep, bool kExtras>
std::unique_ptr<EngineBase> make_variant(const WorldDef& def, std::vector<BallDef>* release) {
  return std::make_unique<Engine<Flight, kBallBall, kStep, kExtras>>(def, release);
}

}  // namespace turtlegas::sim::detail

/// The explicit instantiation of one row of the table in factory.cpp (see variant_seam.hpp).
#define TURTLEGAS_ENGINE_VARIANT(flight, balls, mode, extras)                                   \
  namespace turtlegas::sim::detail {                                                             \
  template std::unique_ptr<EngineBase> make_variant<flight, variant::balls, variant::mode, variant::extras>( \
      const WorldDef&, std::vector<BallDef>*);                                                   \
  }
