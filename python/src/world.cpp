// SPDX-License-Identifier: MIT
#include "world.hpp"

#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <utility>

#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/formats/event_log.hpp"
#include "turtlegas/formats/observables.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/sim/format.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/turtle/event_names.hpp"
#include "turtlegas/turtle/game.hpp"
#include "turtlegas/world/file_error.hpp"
#include "turtlegas/world/world_file.hpp"

namespace turtlegas::python {
namespace {

// Every world server of a process runs its programs on one thread at a time (fiber.hpp: the
// fibers' fault handling is process-wide). Runs of worlds with turtles take turns on this lock,
// with the GIL released, so that Python threads may run several worlds without breaking that.
std::mutex& server_runs() {
  static std::mutex m;
  return m;
}

sim::Vec2 vec(std::pair<double, double> p) { return {p.first, p.second}; }

// A Python program's stack: the interpreter's frames of one resumption of its generator.
constexpr std::size_t python_stack_bytes = 512 * 1024;

/// The bare engine's events named as the event-log writer names them (formats::RunNames), from
/// the scene (spawned balls appended) and the engine's walls (walls added included).
struct BareNames {
  const sim::WorldDef& def;
  const sim::World& world;
  std::string_view ball(std::size_t i) const { return def.balls[i].id; }
  std::string_view wall(std::size_t i) const { return world.walls()[i].id; }
  std::string_view turtle(std::size_t i) const { return def.turtles[i].id; }
};

/// An (n, 2) array of doubles filled by f(i) -> Vec2.
template <class F>
py::array_t<double> pairs(std::size_t n, F&& f) {
  py::array_t<double> a({n, std::size_t{2}});
  auto m = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < n; ++i) {
    const sim::Vec2 v = f(i);
    m(i, 0) = v.x;
    m(i, 1) = v.y;
  }
  return a;
}

/// A read-only 1-D array that owns `values`: handed out many times without a copy.
py::array frozen(std::vector<double> values) {
  auto* owned = new std::vector<double>(std::move(values));
  py::capsule free(owned, [](void* p) { delete static_cast<std::vector<double>*>(p); });
  py::array a(py::dtype::of<double>(), {owned->size()}, {sizeof(double)}, owned->data(), free);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

}  // namespace

std::unique_ptr<World> World::load(const py::object& source, const std::string& mode, std::optional<double> dt,
                                   const py::dict& programs, bool events, bool unwrap) {
  std::unique_ptr<World> w(new World());
  const std::optional<sim::Mode> m = sim::mode_from_string(mode);
  if (!m) throw std::invalid_argument("mode must be \"exact\" or \"step\", got \"" + mode + "\"");
  w->mode_ = *m;
  // The built-in controllers, and `python`: the program World.load was given for the turtle.
  w->programs_ = std::make_shared<Programs>();
  w->registry_ = controllers::builtin_registry();
  w->registry_.add(python_controller, python_program(w->programs_), "a Python program (World.load's programs)");
  if (py::isinstance<py::dict>(source)) {
    const std::string text = py::module_::import("json").attr("dumps")(source).cast<std::string>();
    w->scene_ = world::parse_scene(text, "<dict>", w->registry_);
  } else {
    const std::string path = py::str(py::module_::import("os").attr("fspath")(source));
    w->scene_ = world::load_scene(path, w->registry_);
  }
  world::Scene& scene = w->scene_;
  if (dt) {
    if (!(*dt > 0.0) || !std::isfinite(*dt)) throw std::invalid_argument("dt must be a number of seconds > 0");
    scene.def.dt = *dt;
  }
  for (const auto& [key, program] : programs) {
    const std::string id = key.cast<std::string>();
    std::size_t k = 0;
    while (k < scene.def.turtles.size() && scene.def.turtles[k].id != id) ++k;
    if (k == scene.def.turtles.size()) {
      std::string known;
      for (const auto& t : scene.def.turtles) known += (known.empty() ? "" : ", ") + t.id;
      throw std::invalid_argument("programs: the world has no turtle '" + id + "'; its turtles: " +
                                  (known.empty() ? "none" : known));
    }
    if (!PyCallable_Check(program.ptr()))
      throw std::invalid_argument("programs['" + id + "'] must be a generator function (a Python program)");
    scene.programs[k].controller = python_controller;
    w->programs_->functions[id] = py::reinterpret_borrow<py::object>(program);
  }
  bool python = false;
  for (std::size_t k = 0; k < scene.programs.size(); ++k) {
    if (scene.programs[k].controller != python_controller) continue;
    python = true;
    if (!w->programs_->functions.count(scene.def.turtles[k].id))
      throw std::invalid_argument("turtle '" + scene.def.turtles[k].id + "' runs the controller \"python\": give its "
                                  "program to World.load (programs={\"" + scene.def.turtles[k].id + "\": ...})");
  }
  w->log_events_ = events;
  if (scene.def.turtles.empty()) {
    w->bare_.emplace(scene.def, w->mode_);
    if (events) w->bare_->set_event_log(&w->engine_events_);
  } else {
    w->changes_ = std::make_shared<ChangeQueue>();
    turtle::ServerOptions options;
    options.mode = w->mode_;
    options.input = w->changes_;
    if (python) {
      // The interpreter's frames sit on the program's stack between yields, and a program may
      // think for long between commands (numpy, say): a larger stack, no busy-loop watchdog.
      options.stack_bytes = std::max<std::size_t>(options.stack_bytes, python_stack_bytes);
      options.program_budget = 0.0;
    }
    w->server_ = world::make_server(scene, w->registry_, options);
    if (events) w->server_->set_event_log(&w->server_events_);
  }
  const sim::EffectsDef& fx = scene.def.effects;
  const bool fields = fx.gravity.x != 0.0 || fx.gravity.y != 0.0 || fx.electric.x != 0.0 || fx.electric.y != 0.0;
  w->unwrap_ = unwrap && scene.def.arena.boundary == sim::Boundary::periodic && !fields;
  w->note_new_balls();
  return w;
}

World::~World() {
  // The server first: its programs' coroutines are unwound while what they use is alive.
  server_.reset();
}

void World::require_runnable() const {
  if (running_) throw std::logic_error("the world is running (a program may not run its own world)");
  if (!broken_.empty()) throw std::runtime_error("the world cannot run on: " + broken_ + "; load it again");
}

void World::run(double until) {
  require_runnable();
  if (!(until >= time()) || !std::isfinite(until))
    throw std::invalid_argument("run(until): until must be a time >= the world's (" + sim::format_number(time()) + " s)");
  running_ = true;
  try {
    py::gil_scoped_release free;
    std::unique_lock<std::mutex> lock;
    if (server_) lock = std::unique_lock<std::mutex>(server_runs());
    advance(until);
  } catch (const std::exception& e) {
    running_ = false;
    broken_ = e.what();
    take_events();
    throw;
  }
  running_ = false;
  take_events();
  if (programs_->error) {  // a program raised: its turtle stopped (a `fault` event), the run went on
    py::error_already_set e = std::move(*programs_->error);
    programs_->error.reset();
    throw e;
  }
  if (changes_ && !changes_->refused.empty()) {
    std::string all;
    for (const std::string& s : changes_->refused) all += (all.empty() ? "" : "; ") + s;
    changes_->refused.clear();
    throw std::invalid_argument("the world server refused a change at its boundary (the others were made): " + all);
  }
}

void World::advance(double until) {
  run_in_reads(until, [this](double t) {
    if (server_) server_->run_until(t);
    else bare_->advance_to(t);
  });
}

void World::run_in_reads(double until, const std::function<void(double)>& advance) {
  if (!unwrap_) {
    advance(until);
    return;
  }
  const sim::ArenaDef& a = scene_.def.arena;
  const double side = std::min(a.width, a.height);
  double fastest_turtle = 0.0;  // a turtle's rim moves at most speed + turn rate x radius
  for (const sim::TurtleDef& t : scene_def().turtles) fastest_turtle = std::max(fastest_turtle, t.speed + t.turn_rate * t.radius);
  for (;;) {
    // In a periodic arena without fields the balls' kinetic energy never grows (e <= 1), save what
    // turtles give them (at most twice a turtle's rim speed): no ball can go faster than all of it
    // in the lightest ball. Read between runs of at most a quarter side at that speed, the nearest
    // image of each displacement is the true one.
    const sim::World& w = engine();
    double kinetic = 0.0;
    for (std::size_t i = 0; i < w.ball_count(); ++i) {
      const sim::BallState b = w.ball(i);
      if (b.alive) kinetic += 0.5 * w.mass(i) * sim::dot(b.vel, b.vel);
    }
    const double fastest = std::sqrt(2.0 * kinetic / min_mass_) + 2.0 * fastest_turtle;
    const double t = time();
    const double next = fastest > 0.0 ? std::min(until, t + 0.25 * side / fastest) : until;
    if (next > t) advance(next);
    note_new_balls();
    for (const std::size_t i : restart_) {
      const sim::Vec2 at = w.ball(i).pos;
      unwrapped_[2 * i] = last_wrapped_[2 * i] = at.x;
      unwrapped_[2 * i + 1] = last_wrapped_[2 * i + 1] = at.y;
      images_[2 * i] = images_[2 * i + 1] = 0.0;
    }
    restart_.clear();
    // Wrapped position plus whole periods crossed, counted: the same wherever the run stopped.
    for (std::size_t i = 0; i < w.ball_count(); ++i) {
      const sim::BallState b = w.ball(i);
      if (!b.alive) continue;
      images_[2 * i] -= std::round((b.pos.x - last_wrapped_[2 * i]) / a.width);
      images_[2 * i + 1] -= std::round((b.pos.y - last_wrapped_[2 * i + 1]) / a.height);
      unwrapped_[2 * i] = b.pos.x + images_[2 * i] * a.width;
      unwrapped_[2 * i + 1] = b.pos.y + images_[2 * i + 1] * a.height;
      last_wrapped_[2 * i] = b.pos.x;
      last_wrapped_[2 * i + 1] = b.pos.y;
    }
    if (!(next < until)) return;
  }
}

void World::note_new_balls() {
  const sim::World& w = engine();
  for (std::size_t i = unwrapped_.size() / 2; i < w.ball_count(); ++i) {
    const sim::BallState b = w.ball(i);
    unwrapped_.insert(unwrapped_.end(), {b.pos.x, b.pos.y});
    last_wrapped_.insert(last_wrapped_.end(), {b.pos.x, b.pos.y});
    images_.insert(images_.end(), {0.0, 0.0});
    min_mass_ = i == 0 ? w.mass(i) : std::min(min_mass_, w.mass(i));
  }
}

double World::time() const { return engine().time(); }

std::string World::mode() const { return std::string(sim::to_string(mode_)); }

py::array_t<double> World::positions() const {
  const sim::World& w = engine();
  return pairs(w.ball_count(), [&](std::size_t i) { return w.ball(i).pos; });
}

py::array_t<double> World::velocities() const {
  const sim::World& w = engine();
  return pairs(w.ball_count(), [&](std::size_t i) { return w.ball(i).vel; });
}

py::array_t<bool> World::alive() const {
  const sim::World& w = engine();
  py::array_t<bool> a(w.ball_count());
  auto m = a.mutable_unchecked<1>();
  for (std::size_t i = 0; i < w.ball_count(); ++i) m(i) = w.ball(i).alive;
  return a;
}

void World::refresh_ball_arrays() {
  const sim::World& w = engine();
  if (arrays_for_ == w.ball_count()) return;
  std::vector<double> r(w.ball_count()), m(w.ball_count()), q(w.ball_count());
  const sim::WorldDef& def = scene_def();
  for (std::size_t i = 0; i < w.ball_count(); ++i) {
    r[i] = w.radius(i);
    m[i] = w.mass(i);
    q[i] = def.balls[i].charge;
  }
  radii_ = frozen(std::move(r));
  masses_ = frozen(std::move(m));
  charges_ = frozen(std::move(q));
  arrays_for_ = w.ball_count();
}

py::array World::radii() {
  refresh_ball_arrays();
  return radii_;
}
py::array World::masses() {
  refresh_ball_arrays();
  return masses_;
}
py::array World::charges() {
  refresh_ball_arrays();
  return charges_;
}

py::list World::ball_ids() const {
  py::list ids;
  for (const sim::BallDef& b : scene_def().balls) ids.append(b.id);
  return ids;
}

py::object World::unwrapped() {
  if (scene_.def.arena.boundary != sim::Boundary::periodic) return positions();  // nothing to unwrap
  if (!unwrap_) return py::none();
  const std::size_t n = unwrapped_.size() / 2;
  return pairs(n, [&](std::size_t i) { return sim::Vec2{unwrapped_[2 * i], unwrapped_[2 * i + 1]}; });
}

py::array_t<double> World::turtle_positions() const {
  const sim::World& w = engine();
  return pairs(w.turtle_count(), [&](std::size_t i) { return w.turtle(i).pos; });
}

py::array_t<double> World::headings() const {
  const sim::World& w = engine();
  py::array_t<double> a(w.turtle_count());
  auto m = a.mutable_unchecked<1>();
  for (std::size_t i = 0; i < w.turtle_count(); ++i) m(i) = sim::wrap_degrees(sim::to_degrees(w.turtle(i).heading));
  return a;
}

py::list World::turtle_ids() const {
  py::list ids;
  for (const sim::TurtleDef& t : scene_def().turtles) ids.append(t.id);
  return ids;
}

double World::energy() const { return engine().energy(); }

py::dict World::stats() const {
  const sim::Stats& s = engine().stats();
  py::dict d;
  d["ball_ball"] = s.ball_ball;
  d["ball_wall"] = s.ball_wall;
  d["ball_wall_end"] = s.ball_wall_end;
  d["exits"] = s.exits;
  d["wedged"] = s.wedged;
  d["crushed"] = s.crushed;
  d["turtle_wall"] = s.turtle_wall;
  d["turtle_wall_end"] = s.turtle_wall_end;
  d["turtle_turtle"] = s.turtle_turtle;
  d["turtle_ball"] = s.turtle_ball;
  d["collisions"] = s.collisions();
  d["cell_crossings"] = s.cell_crossings;
  d["steps"] = s.steps;
  d["events"] = s.events;
  return d;
}

void World::take_events() {
  for (turtle::LogEvent& e : server_events_) pending_.push_back(std::move(e));
  server_events_.clear();
  if (bare_) {
    const BareNames names{scene_.def, *bare_};
    for (const sim::Event& e : engine_events_) {
      const turtle::EventIds ids = turtle::name_event(e, names);
      pending_.push_back({e.t, std::string(sim::to_string(e.kind)), std::string(ids.a),
                          ids.b ? std::string(*ids.b) : std::string(), {}, 0.0, {},
                          ids.c ? std::string(*ids.c) : std::string(), {}});
    }
  }
  engine_events_.clear();
}

std::string World::event_lines() {
  take_events();
  std::string out;
  for (const turtle::LogEvent& e : pending_) formats::append_event(out, formats::event_line(e));
  pending_.clear();
  return out;
}

py::list World::events_list() {
  take_events();
  const py::object event = py::module_::import("turtlegas._turtlegas").attr("Event");
  py::list out;
  for (const turtle::LogEvent& e : pending_) {
    py::tuple sensors(e.sensors.size());
    for (std::size_t k = 0; k < e.sensors.size(); ++k) sensors[k] = py::str(e.sensors[k]);
    out.append(event(e.t, e.kind, e.a, e.b, e.c, sensors, e.bearing, e.message, e.extra));
  }
  pending_.clear();
  return out;
}

py::array World::events_array() {
  take_events();
  std::size_t kind = 1, id = 1, sensors = 1, message = 1, extra = 1;
  auto joined = [](const std::vector<std::string>& v) {
    std::string s;
    for (const std::string& x : v) s += (s.empty() ? "" : ",") + x;
    return s;
  };
  for (const turtle::LogEvent& e : pending_) {
    kind = std::max(kind, e.kind.size());
    id = std::max({id, e.a.size(), e.b.size(), e.c.size()});
    sensors = std::max(sensors, joined(e.sensors).size());
    message = std::max(message, e.message.size());
    extra = std::max(extra, e.extra.size());
  }
  auto u = [](std::size_t n) { return "U" + std::to_string(n); };
  py::list fields;
  fields.append(py::make_tuple("t", "f8"));
  fields.append(py::make_tuple("kind", u(kind)));
  fields.append(py::make_tuple("a", u(id)));
  fields.append(py::make_tuple("b", u(id)));
  fields.append(py::make_tuple("c", u(id)));
  fields.append(py::make_tuple("sensors", u(sensors)));
  fields.append(py::make_tuple("bearing", "f8"));
  fields.append(py::make_tuple("message", u(message)));
  fields.append(py::make_tuple("extra", u(extra)));
  py::list rows;
  for (const turtle::LogEvent& e : pending_)
    rows.append(py::make_tuple(e.t, e.kind, e.a, e.b, e.c, joined(e.sensors), e.bearing, e.message, e.extra));
  pending_.clear();
  const py::module_ np = py::module_::import("numpy");
  return np.attr("array")(rows, np.attr("dtype")(fields));
}

py::object World::observe(double until, double from, double window, int samples, const std::string& axis, int bins,
                          int speed_bins) {
  require_runnable();
  if (server_)
    throw std::invalid_argument("observe measures a gas run by the bare engine (as `turtlegas run --observe`); this "
                                "world has turtles");
  formats::ObserveOptions o;
  o.from = from;
  o.window = window;
  o.samples = samples;
  if (axis != "x" && axis != "y") throw std::invalid_argument("axis must be \"x\" or \"y\", got \"" + axis + "\"");
  o.axis = axis[0];
  o.profile_bins = bins;
  o.speed_bins = speed_bins;
  if (const std::string bad = formats::check_observe(o, time(), until); !bad.empty()) throw std::invalid_argument(bad);
  formats::Observer observer(*bare_, scene_.def, o, until);
  running_ = true;
  try {
    py::gil_scoped_release free;
    run_in_reads(until, [&observer](double t) { observer.advance_to(t); });
  } catch (const std::exception& e) {
    running_ = false;
    broken_ = e.what();
    throw;
  }
  running_ = false;
  observer.detach();
  take_events();
  return py::module_::import("json").attr("loads")(observer.result().dump());
}

void World::check_new_id(const std::string& id) const {
  if (id.empty()) throw std::invalid_argument("give the body an id");
  bool taken = false;
  for (const sim::WallDef& w : engine().walls()) taken = taken || w.id == id;
  for (const sim::BallDef& b : scene_def().balls) taken = taken || b.id == id;
  for (const sim::TurtleDef& t : scene_def().turtles) taken = taken || t.id == id;
  if (taken) throw std::invalid_argument("id '" + id + "' is taken; give it an id that no wall, ball or turtle has");
}

void World::log_change(const char* kind, const std::string& id, const std::string& what) {
  if (!log_events_) return;
  take_events();  // the engine's events so far come first
  pending_.push_back({time(), kind, id, what, {}, 0.0, {}, {}, {}});
}

void World::refuse(const std::string& who, const sim::PlacementError& e) const {
  using Obstacle = sim::PlacementError::Obstacle;
  std::string what;
  switch (e.obstacle) {
    case Obstacle::ball: what = "ball '" + scene_def().balls[e.index].id + "'"; break;
    case Obstacle::turtle: what = "turtle '" + scene_def().turtles[e.index].id + "'"; break;
    case Obstacle::wall: what = "wall '" + engine().walls()[e.index].id + "'"; break;
    case Obstacle::none: throw std::invalid_argument(who + ": " + e.what());
  }
  throw std::invalid_argument(who + " would overlap " + what + " by " + sim::format_number(e.depth) +
                              " (world units); place it clear of it");
}

std::optional<std::size_t> World::live_ball(const std::string& id) const {
  const sim::WorldDef& def = scene_def();
  for (std::size_t i = 0; i < def.balls.size(); ++i)
    if (def.balls[i].id == id && engine().ball(i).alive) return i;
  return std::nullopt;
}

void World::spawn_ball(const std::string& id, std::pair<double, double> pos, std::pair<double, double> vel,
                       double radius, double mass, double charge) {
  require_runnable();
  sim::BallDef b;
  b.id = id;
  b.pos = vec(pos);
  b.vel = vec(vel);
  b.radius = radius;
  b.mass = mass;
  b.charge = charge;
  check_new_id(id);
  if (server_) {
    if (auto problem = server_->placement_problem(b.pos, b.radius)) throw std::invalid_argument("ball '" + id + "': " + *problem);
    changes_->changes.push_back([b](turtle::WorldServer& s) { s.spawn_ball(b); });
    return;
  }
  try {
    bare_->spawn_ball(b);
  } catch (const sim::PlacementError& e) {
    refuse("ball '" + id + "'", e);
  }
  scene_.def.balls.push_back(b);
  note_new_balls();
  log_change("spawn", id, "ball");
}

void World::spawn_turtle(const std::string& id, std::pair<double, double> pos, double heading, double radius,
                         double speed, double turn_rate, const std::string& controller, const py::object& params,
                         const py::object& program) {
  require_runnable();
  if (!server_)
    throw std::invalid_argument("this world has no turtles, so its engine keeps no turtle lists: give the world file a "
                                "turtle to spawn turtles into it");
  check_new_id(id);
  sim::TurtleDef d;
  d.id = id;
  d.pos = vec(pos);
  d.heading = sim::to_radians(sim::wrap_degrees(heading));
  d.radius = radius;
  d.speed = speed;
  d.turn_rate = sim::to_radians(turn_rate);
  if (auto problem = server_->placement_problem(d.pos, d.radius)) throw std::invalid_argument("turtle '" + id + "': " + *problem);
  turtle::TurtleProgram p;
  if (!params.is_none())
    p.params = nlohmann::json::parse(py::module_::import("json").attr("dumps")(params).cast<std::string>());
  if (!program.is_none()) {
    if (!PyCallable_Check(program.ptr())) throw std::invalid_argument("program must be a generator function");
    p.controller = python_controller;
    programs_->functions[id] = program;
  } else {
    if (!registry_.find(controller))
      throw std::invalid_argument("turtle '" + id + "': " + registry_.not_registered(controller));
    p.controller = controller;
  }
  changes_->changes.push_back([d, p](turtle::WorldServer& s) { s.spawn_turtle(d, p); });
}

void World::remove(const std::string& id) {
  require_runnable();
  if (server_) {
    if (!server_->body_is_ball(id)) throw std::invalid_argument("no ball or turtle '" + id + "' is in the world; name one that is");
    changes_->changes.push_back([id](turtle::WorldServer& s) { s.remove_body(id); });
    return;
  }
  const std::optional<std::size_t> i = live_ball(id);
  if (!i) throw std::invalid_argument("no ball or turtle '" + id + "' is in the world; name one that is");
  bare_->remove_ball(*i);
  log_change("remove", id, "ball");
}

void World::teleport(const std::string& id, std::pair<double, double> pos, const py::object& vel, const py::object& heading) {
  require_runnable();
  const sim::Vec2 p = vec(pos);
  const std::optional<sim::Vec2> v =
      vel.is_none() ? std::nullopt : std::optional<sim::Vec2>(vec(vel.cast<std::pair<double, double>>()));
  const std::optional<double> h = heading.is_none() ? std::nullopt : std::optional<double>(heading.cast<double>());
  if (server_) {
    const std::optional<bool> ball = server_->body_is_ball(id);
    if (!ball) throw std::invalid_argument("no ball or turtle '" + id + "' is in the world; name one that is");
    if (*ball && h) throw std::invalid_argument("ball '" + id + "': a ball has no heading; give vel");
    if (!*ball && v) throw std::invalid_argument("turtle '" + id + "': a turtle stands still where it lands; give heading");
    const std::size_t k = [&] {
      std::size_t k = 0;
      for (const auto& t : server_->scene().turtles) {
        if (t.id == id) break;
        ++k;
      }
      return k;
    }();
    const double r = *ball ? server_->scene().balls[*live_ball(id)].radius : server_->scene().turtles[k].radius;
    if (auto problem = server_->placement_problem(p, r, id))
      throw std::invalid_argument((*ball ? "ball '" : "turtle '") + id + "': " + *problem);
    if (*ball) {
      const std::size_t i = *live_ball(id);
      changes_->changes.push_back([this, id, i, p, v](turtle::WorldServer& s) {
        s.teleport_ball(id, p, v ? *v : s.world().ball(i).vel);
        restart_.push_back(i);
      });
    } else {
      changes_->changes.push_back([id, k, p, h](turtle::WorldServer& s) {
        s.teleport_turtle(id, p, h ? *h : sim::to_degrees(s.world().turtle(k).heading));
      });
    }
    return;
  }
  const std::optional<std::size_t> i = live_ball(id);
  if (!i) throw std::invalid_argument("no ball '" + id + "' is in the world; name one that is");
  if (h) throw std::invalid_argument("ball '" + id + "': a ball has no heading; give vel");
  try {
    bare_->teleport_ball(*i, p, v ? *v : bare_->ball(*i).vel);
  } catch (const sim::PlacementError& e) {
    refuse("ball '" + id + "'", e);
  }
  restart_.push_back(*i);
  log_change("teleport", id, "ball");
}

void World::add_wall(const std::string& id, std::pair<double, double> from, std::pair<double, double> to) {
  require_runnable();
  check_new_id(id);
  sim::WallDef w;
  w.id = id;
  w.from = vec(from);
  w.to = vec(to);
  if (server_) {
    changes_->changes.push_back([w](turtle::WorldServer& s) { s.add_wall(w); });
    return;
  }
  bare_->add_wall(w);  // throws std::invalid_argument, changing nothing
  log_change("wall-added", id, {});
}

void bind_world(py::module_& m) {
  // turtlegas.WorldError (a ValueError): str() is the loader's one line; .file, .path (the JSON
  // pointer, "" when none applies), .reason, .line and .column (JSON syntax errors) are its parts.
  static py::exception<world::WorldFileError> world_error(m, "WorldError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const world::WorldFileError& e) {
      py::object error = py::reinterpret_borrow<py::object>(world_error.ptr())(e.what());
      error.attr("file") = e.file;
      error.attr("path") = e.json_path;
      error.attr("reason") = e.reason;
      error.attr("line") = e.line;
      error.attr("column") = e.column;
      PyErr_SetObject(world_error.ptr(), error.ptr());
    }
  });
  m.attr("Event") = py::module_::import("collections").attr("namedtuple")("Event", "t kind a b c sensors bearing message extra");

  using P = std::pair<double, double>;
  py::class_<World>(m, "World", "A world file's run, in process (docs/python.md)")
      .def_static("load", &World::load, py::return_value_policy::take_ownership, py::arg("source"), py::arg("mode") = "exact", py::arg("dt") = py::none(),
                  py::arg("programs") = py::dict(), py::arg("events") = true, py::arg("unwrap") = true,
                  "Loads a world file (a path) or a world given as a dict. mode: \"exact\" or \"step\"; dt: the "
                  "control step (s), overriding the file's; programs: {turtle id: generator function}; events: keep "
                  "the event log; unwrap: follow positions across a periodic arena's seams")
      .def("run", &World::run, py::arg("until"), "Runs to time `until` (seconds); the GIL is released meanwhile")
      .def("advance", [](World& w, double dt) { w.run(w.time() + dt); }, py::arg("dt"), "Runs for dt more seconds")
      .def_property_readonly("time", &World::time, "Simulated time, seconds")
      .def_property_readonly("mode", &World::mode, "\"exact\" or \"step\"")
      .def_property_readonly("dt", &World::dt, "The control step (step mode's step), seconds")
      .def_property_readonly("positions", &World::positions, "Balls' centres now, (n, 2); a copy")
      .def_property_readonly("velocities", &World::velocities, "Balls' velocities now, (n, 2); a copy")
      .def_property_readonly("alive", &World::alive, "Per ball: still in the world (not exited, crushed or removed)")
      .def_property_readonly("radii", &World::radii, "Balls' radii, read-only (the module's own array, not copied)")
      .def_property_readonly("masses", &World::masses, "Balls' masses, read-only (the module's own array, not copied)")
      .def_property_readonly("charges", &World::charges, "Balls' charges, read-only (the module's own array, not copied)")
      .def_property_readonly("ball_ids", &World::ball_ids, "Balls' ids, by index")
      .def_property_readonly("unwrapped", &World::unwrapped,
                             "Balls' centres followed across a periodic arena's seams, (n, 2); the positions in "
                             "other arenas; None when not followed (unwrap=False, or gravity or an electric field)")
      .def_property_readonly("turtle_positions", &World::turtle_positions, "Turtles' centres now, (k, 2)")
      .def_property_readonly("headings", &World::headings, "Turtles' headings now, degrees (Logo: 0 is +y, clockwise)")
      .def_property_readonly("turtle_ids", &World::turtle_ids, "Turtles' ids, by index")
      .def_property_readonly("energy", &World::energy, "Kinetic plus potential energy of the live balls")
      .def_property_readonly("stats", &World::stats, "The engine's counters (collisions, events, ...)")
      .def("events", &World::events_array,
           "The events since the last call, as a numpy structured array (fields t, kind, a, b, c, sensors, bearing, "
           "message, extra; sensors comma-separated)")
      .def("event_tuples", &World::events_list, "The events since the last call, as turtlegas.Event named tuples")
      .def("event_lines", &World::event_lines,
           "The events since the last call, as the event log's lines (`turtlegas run --events`)")
      .def("observe", &World::observe, py::arg("until"), py::arg("start") = 0.0, py::arg("window") = 0.0,
           py::arg("samples") = 20, py::arg("axis") = "y", py::arg("bins") = 20, py::arg("speed_bins") = 40,
           "Runs to `until` observing the gas as `turtlegas run --observe` does; returns its figures as a dict")
      .def("spawn_ball", &World::spawn_ball, py::arg("id"), py::arg("pos"), py::arg("vel") = P{0.0, 0.0},
           py::arg("radius") = 1.0, py::arg("mass") = 1.0, py::arg("charge") = 0.0,
           "Adds a ball: now without turtles, at the next control boundary with turtles")
      .def("spawn_turtle", &World::spawn_turtle, py::arg("id"), py::arg("pos"), py::arg("heading") = 0.0, py::arg("radius") = 10.0, py::arg("speed") = 30.0,
          py::arg("turn_rate") = 90.0, py::arg("controller") = "script", py::arg("params") = py::none(),
          py::arg("program") = py::none(),
          "Adds a turtle at the next control boundary, running a registered controller or a Python program")
      .def("remove", &World::remove, py::arg("id"), "Removes a ball or a turtle")
      .def("teleport", &World::teleport, py::arg("id"), py::arg("pos"), py::arg("vel") = py::none(),
           py::arg("heading") = py::none(), "Moves a ball (with vel) or a turtle (with heading, degrees)")
      .def("add_wall", &World::add_wall, py::arg("id"), py::arg("start"), py::arg("end"), "Adds a wall");
}

}  // namespace turtlegas::python
