// SPDX-License-Identifier: MIT
// VecWorld: the copies, their control step (the order is in vec_world.hpp) and their observations.
#include "turtlegas/learn/vec_world.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <numbers>
#include <thread>

#include "turtlegas/sim/angles.hpp"
#include "turtlegas/sim/ray_cast.hpp"
#include "ring_cast.hpp"
#include "worker_pool.hpp"

namespace turtlegas::learn {
namespace {

/// What VecWorld keeps of a turtle's program: its sensors.
struct TurtleSenses {
  std::vector<turtle::SensorArc> arcs;  // degrees, as the runtime keeps them
  // Every range sensor's rays, in declaration order: the sine and cosine of each ray's bearing
  // (so that a ray's direction is the heading's turned by it, one sincos a turtle) and its range.
  std::vector<double> sin_bearing, cos_bearing, ranges;
  std::vector<double> noise, dropout;  // each ray's sensor's (RangeSensor::noise, dropout)
  bool noisy = false;
  double reach = 0.0;  // the longest range
  bool gps = false;
};

/// Bit k set when arc k holds `bearing` (degrees clockwise from the heading): the runtime's rule
/// (turtle_runtime/src/sensors.hpp), over the world file's arcs.
std::uint64_t arcs_for(const std::vector<turtle::SensorArc>& arcs, double bearing) {
  std::uint64_t fired = 0;
  for (std::size_t k = 0; k < arcs.size() && k < 64; ++k) {
    const double span = arcs[k].to - arcs[k].from;
    if (sim::wrap_degrees(bearing - arcs[k].from) < (span >= 360.0 ? 360.0 : sim::wrap_degrees(span)))
      fired |= std::uint64_t{1} << k;
  }
  return fired;
}

/// A 64-bit mix (splitmix64's finaliser): copy i's streams from (seed, i, purpose), unrelated for
/// neighbouring seeds.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

double uniform01(std::mt19937_64& g) { return static_cast<double>(g() >> 11) * 0x1.0p-53; }

float clamp_action(float a) {
  if (!(a == a)) return 0.0f;  // NaN: no motion
  return std::clamp(a, -1.0f, 1.0f);
}

}  // namespace

class VecWorld::Impl {
 public:
  struct Copy {
    std::optional<sim::World> world;
    std::mt19937_64 actions_rng;
    std::mt19937_64 noise_rng;  // the range sensors' noise, drawn in turtle and ray order
    std::uint64_t steps = 0;
    std::uint64_t contacts = 0;
    bool terminated = false;
    bool truncated = false;
    std::vector<std::uint64_t> touched;  // per turtle: arcs fired in the last step
    std::vector<double> moved;           // per turtle: units driven in the last step (signed)
    std::vector<double> turned;          // per turtle: radians turned in the last step (clockwise)
    std::vector<double> turn_sign, move_sign;  // of the commands given this step
    std::vector<sim::TurtleContact> scratch;
    std::optional<detail::RingCaster> caster;  // when it applies to the scene (ring_cast.hpp)
    std::vector<sim::Vec2> dirs;
    std::vector<sim::RayHit> hits;
  };

  Impl(const world::Scene& scene, std::size_t n, VecWorldOptions opt)
      : def(scene.def), options(opt), pool(opt.threads ? opt.threads : std::max(1u, std::thread::hardware_concurrency())) {
    if (n == 0) throw std::invalid_argument("VecWorld needs at least one copy of the world (n = 0)");
    if (def.turtles.empty())
      throw std::invalid_argument("VecWorld drives turtles, and world '" + def.name + "' has none: add a turtle to its \"turtles\"");
    // The engine is built once here, so that a scene it refuses fails now rather than at reset.
    sim::World probe(def, options.mode);
    for (std::size_t k = 0; k < def.turtles.size(); ++k) {
      TurtleSenses s;
      const turtle::TurtleProgram& p = scene.programs.at(k);
      s.arcs = p.sensors;
      for (const turtle::RangeSensor& r : p.senses)
        for (double b : r.bearings) {
          s.sin_bearing.push_back(std::sin(sim::to_radians(b)));
          s.cos_bearing.push_back(std::cos(sim::to_radians(b)));
          s.ranges.push_back(r.range);
          s.noise.push_back(r.noise);
          s.dropout.push_back(r.dropout);
          s.noisy = s.noisy || r.noise > 0.0 || r.dropout > 0.0;
          s.reach = std::max(s.reach, r.range);
        }
      s.gps = p.gps;
      lay.touch_count = std::max(lay.touch_count, std::min<std::size_t>(s.arcs.size(), 64));
      lay.range_count = std::max(lay.range_count, s.ranges.size());
      if (s.gps) lay.gps_count = 1;
      senses.push_back(std::move(s));
      ids.push_back(def.turtles[k].id);
    }
    lay.touch = 0;
    lay.range = lay.touch + lay.touch_count;
    lay.odometry = lay.range + lay.range_count;
    lay.heading = lay.odometry + 2;
    lay.gps = lay.heading + 2;
    lay.size = lay.gps + 2 * lay.gps_count;
    copies.resize(n);
    const std::size_t t = def.turtles.size();
    for (Copy& c : copies) {
      c.touched.assign(t, 0);
      c.moved.assign(t, 0.0);
      c.turned.assign(t, 0.0);
      c.turn_sign.assign(t, 0.0);
      c.move_sign.assign(t, 0.0);
    }
  }

  std::size_t turtles() const { return def.turtles.size(); }
  std::size_t action_size() const { return options.actions == ActionKind::logo ? 1 : 2; }

  void check_obs(std::span<float> obs) const {
    if (obs.size() != copies.size() * turtles() * lay.size)
      throw std::invalid_argument("VecWorld: the observation buffer holds " + std::to_string(obs.size()) + " floats; it needs " +
                                  std::to_string(copies.size()) + " copies x " + std::to_string(turtles()) + " turtles x " +
                                  std::to_string(lay.size) + " = " + std::to_string(copies.size() * turtles() * lay.size));
  }

  /// Copy i rebuilt from the scene, its turtles scattered (random_start) and its streams seeded.
  void reset_copy(std::size_t i, std::uint64_t seed) {
    Copy& c = copies[i];
    c.world.reset();
    c.world.emplace(def, options.mode);
    sim::World& w = *c.world;
    std::mt19937_64 place(mix(mix(seed) ^ mix(2 * i + 1)));
    c.actions_rng.seed(mix(mix(seed + 1) ^ mix(2 * i + 2)));
    c.noise_rng.seed(mix(mix(seed + 2) ^ mix(2 * i + 1)));
    if (options.random_start) {
      const double width = def.arena.width, height = def.arena.height;
      for (std::size_t k = 0; k < turtles(); ++k) {
        const double r = def.turtles[k].radius;
        bool placed = false;
        // A free pose is found in a few draws unless the arena is crowded; 10000 refusals say it is.
        for (int attempt = 0; attempt < 10000 && !placed; ++attempt) {
          const sim::Vec2 pos{r + (width - 2 * r) * uniform01(place), r + (height - 2 * r) * uniform01(place)};
          const double heading = 2.0 * std::numbers::pi * uniform01(place);
          try {
            w.teleport_turtle(k, pos, heading);
            placed = true;
          } catch (const std::invalid_argument&) {
            // overlaps a wall, a ball or a turtle placed before it: draw again
          }
        }
        if (!placed)
          throw std::runtime_error("VecWorld: no free place for turtle '" + ids[k] + "' in 10000 random draws; the arena is too crowded for random starts (random_start = false keeps the world file's poses)");
      }
    }
    w.take_turtle_contacts();
    if (!c.caster && detail::RingCaster::applies(w, def)) c.caster.emplace(w, def);
    c.steps = 0;
    c.contacts = 0;
    c.terminated = c.truncated = false;
    std::fill(c.touched.begin(), c.touched.end(), 0);
    std::fill(c.moved.begin(), c.moved.end(), 0.0);
    std::fill(c.turned.begin(), c.turned.end(), 0.0);
  }

  /// The step's contacts so far become touch bits, read against each turtle's heading now.
  void collect_contacts(Copy& c) {
    sim::World& w = *c.world;
    c.scratch = w.take_turtle_contacts();
    for (const sim::TurtleContact& tc : c.scratch) {
      if (!w.turtle_alive(tc.turtle)) continue;
      ++c.contacts;
      const double heading_deg = sim::to_degrees(w.turtle(tc.turtle).heading);
      // The contact point lies against the normal (which points from the obstacle to the turtle).
      const double bearing = sim::wrap_degrees(sim::to_degrees(sim::heading_of(-tc.normal)) - heading_deg);
      c.touched[tc.turtle] |= arcs_for(senses[tc.turtle].arcs, bearing);
    }
  }

  void begin_step(Copy& c) {
    std::fill(c.touched.begin(), c.touched.end(), 0);
    std::fill(c.moved.begin(), c.moved.end(), 0.0);
    std::fill(c.turned.begin(), c.turned.end(), 0.0);
    c.contacts = 0;
  }

  void end_step(Copy& c) {
    sim::World& w = *c.world;
    ++c.steps;
    for (std::size_t k = 0; k < turtles(); ++k)
      if (!w.turtle_alive(k)) c.terminated = true;
    if (options.max_steps && c.steps >= options.max_steps) c.truncated = true;
  }

  /// Commands turtle k to turn or move by `amount`, or to stop when it is 0; returns its sign.
  static double command(sim::World& w, std::size_t k, sim::TurtleCommand::Kind kind, double amount) {
    if (amount == 0.0) {
      w.command_turtle(k, {sim::TurtleCommand::Kind::stop, 0.0});
      return 0.0;
    }
    w.command_turtle(k, {kind, amount});
    return amount > 0.0 ? 1.0 : -1.0;
  }

  void step_continuous(std::size_t i, const float* a) {
    Copy& c = copies[i];
    if (c.terminated || c.truncated) return;
    sim::World& w = *c.world;
    begin_step(c);
    const double t0 = w.time(), dt = def.dt;
    const std::size_t n = turtles();
    // 1. The turns, in the first half of the step.
    for (std::size_t k = 0; k < n; ++k) {
      c.turn_sign[k] = c.move_sign[k] = 0.0;
      if (!w.turtle_alive(k)) continue;
      const double x = clamp_action(a[2 * k]), y = clamp_action(a[2 * k + 1]);
      // Wheels (l, r): a differential drive whose full opposite wheels turn at the full rate.
      const double omega = options.actions == ActionKind::wheels ? 0.5 * (x - y) : y;
      const double angle = omega * def.turtles[k].turn_rate * dt * 0.5;
      c.turn_sign[k] = command(w, k, sim::TurtleCommand::Kind::turn, angle);
    }
    w.advance_to(t0 + 0.5 * dt);
    collect_contacts(c);
    // 2. The strokes, in the second half.
    for (std::size_t k = 0; k < n; ++k) {
      if (!w.turtle_alive(k)) continue;
      if (c.turn_sign[k] != 0.0) c.turned[k] = c.turn_sign[k] * w.turtle(k).done;
      const double x = clamp_action(a[2 * k]), y = clamp_action(a[2 * k + 1]);
      const double v = options.actions == ActionKind::wheels ? 0.5 * (x + y) : x;
      const double distance = v * def.turtles[k].speed * dt * 0.5;
      c.move_sign[k] = command(w, k, sim::TurtleCommand::Kind::move, distance);
    }
    w.advance_to(t0 + dt);
    collect_contacts(c);
    for (std::size_t k = 0; k < n; ++k)
      if (c.move_sign[k] != 0.0 && w.turtle_alive(k)) c.moved[k] = c.move_sign[k] * w.turtle(k).done;
    end_step(c);
  }

  void step_logo(std::size_t i, const std::int32_t* a) {
    Copy& c = copies[i];
    if (c.terminated || c.truncated) return;
    sim::World& w = *c.world;
    begin_step(c);
    const double t0 = w.time(), dt = def.dt;
    const std::size_t n = turtles();
    for (std::size_t k = 0; k < n; ++k) {
      c.turn_sign[k] = c.move_sign[k] = 0.0;
      if (!w.turtle_alive(k)) continue;
      const sim::TurtleDef& td = def.turtles[k];
      sim::TurtleCommand cmd;
      switch (static_cast<LogoAction>(a[k])) {
        case LogoAction::forward: cmd = {sim::TurtleCommand::Kind::move, td.speed * dt}, c.move_sign[k] = 1; break;
        case LogoAction::back: cmd = {sim::TurtleCommand::Kind::move, -td.speed * dt}, c.move_sign[k] = -1; break;
        case LogoAction::left: cmd = {sim::TurtleCommand::Kind::turn, -td.turn_rate * dt}, c.turn_sign[k] = -1; break;
        case LogoAction::right: cmd = {sim::TurtleCommand::Kind::turn, td.turn_rate * dt}, c.turn_sign[k] = 1; break;
        default: break;  // wait, and anything out of range
      }
      w.command_turtle(k, cmd);
    }
    w.advance_to(t0 + dt);
    collect_contacts(c);
    for (std::size_t k = 0; k < n; ++k) {
      if (!w.turtle_alive(k)) continue;
      const double done = w.turtle(k).done;
      if (c.move_sign[k] != 0.0) c.moved[k] = c.move_sign[k] * done;
      if (c.turn_sign[k] != 0.0) c.turned[k] = c.turn_sign[k] * done;
    }
    end_step(c);
  }

  /// Sensor noise on the hits of one turtle's rays, as the runtime's Turtle::scan adds it
  /// (turtle_runtime/src/senses.cpp): a hit dropped with probability `dropout`, else a Gaussian of
  /// sd `noise` added (not below 0; beyond the range it reads as nothing). From the copy's stream.
  static void add_noise(Copy& c, const TurtleSenses& ts) {
    auto uniform = [&] { return uniform01(c.noise_rng); };
    for (std::size_t r = 0; r < c.hits.size(); ++r) {
      sim::RayHit& hit = c.hits[r];
      if (!hit.hit() || (ts.noise[r] <= 0.0 && ts.dropout[r] <= 0.0)) continue;
      if (ts.dropout[r] > 0.0 && uniform() < ts.dropout[r]) {
        hit = {};
      } else if (ts.noise[r] > 0.0) {
        // Box-Muller: 1 - u is in (0, 1], so the logarithm is finite.
        const double g = std::sqrt(-2.0 * std::log(1.0 - uniform())) * std::cos(2.0 * std::numbers::pi * uniform());
        hit.distance = std::max(0.0, hit.distance + ts.noise[r] * g);
        if (hit.distance > ts.ranges[r]) hit = {};
      }
    }
  }

  /// Copy i's rows of obs, as its world stands now.
  void observe(std::size_t i, float* obs) {
    Copy& c = copies[i];
    const sim::World& w = *c.world;
    if (c.caster) c.caster->begin(w);
    sim::Ray ray;
    for (std::size_t k = 0; k < turtles(); ++k) {
      float* row = obs + k * lay.size;
      std::fill(row, row + lay.size, 0.0f);
      std::fill(row + lay.range, row + lay.range + lay.range_count, 1.0f);
      for (std::size_t b = 0; b < lay.touch_count; ++b) row[lay.touch + b] = (c.touched[k] >> b) & 1 ? 1.0f : 0.0f;
      row[lay.odometry] = static_cast<float>(c.moved[k]);
      row[lay.odometry + 1] = static_cast<float>(c.turned[k]);
      if (!w.turtle_alive(k)) continue;  // a turtle gone: its rays read nothing, its pose 0
      const sim::TurtleState st = w.turtle(k);
      const double sh = std::sin(st.heading), ch = std::cos(st.heading);
      row[lay.heading] = static_cast<float>(sh);
      row[lay.heading + 1] = static_cast<float>(ch);
      const TurtleSenses& ts = senses[k];
      if (ts.gps) {
        row[lay.gps] = static_cast<float>(st.pos.x);
        row[lay.gps + 1] = static_cast<float>(st.pos.y);
      }
      const std::size_t nr = ts.ranges.size();
      if (nr == 0) continue;
      // Heading h turned by bearing b: (sin(h + b), cos(h + b)), Logo's 0 at +y, clockwise.
      c.dirs.resize(nr);
      for (std::size_t r = 0; r < nr; ++r)
        c.dirs[r] = {sh * ts.cos_bearing[r] + ch * ts.sin_bearing[r], ch * ts.cos_bearing[r] - sh * ts.sin_bearing[r]};
      const sim::Layers& layers = def.turtles[k].layers;
      if (c.caster) {
        c.caster->cast(w, st.pos, layers, static_cast<std::uint32_t>(k), c.dirs, ts.ranges, ts.reach, c.hits);
      } else {
        c.hits.resize(nr);
        ray.origin = st.pos;
        ray.layers = layers;
        ray.self = static_cast<std::uint32_t>(k);
        for (std::size_t r = 0; r < nr; ++r) {
          ray.range = ts.ranges[r];
          ray.dir = c.dirs[r];
          c.hits[r] = w.cast_ray(ray);
        }
      }
      if (ts.noisy) add_noise(c, ts);
      for (std::size_t r = 0; r < nr; ++r)
        if (c.hits[r].hit()) row[lay.range + r] = static_cast<float>(c.hits[r].distance / ts.ranges[r]);
    }
  }

  void check_done_spans(std::span<std::uint8_t> terminated, std::span<std::uint8_t> truncated) const {
    if (terminated.size() != copies.size() || truncated.size() != copies.size())
      throw std::invalid_argument("VecWorld: terminated and truncated hold one flag per copy (" + std::to_string(copies.size()) +
                                  "), not " + std::to_string(terminated.size()) + " and " + std::to_string(truncated.size()));
  }

  sim::WorldDef def;
  VecWorldOptions options;
  detail::WorkerPool pool;
  ObsLayout lay;
  std::vector<TurtleSenses> senses;
  std::vector<std::string> ids;
  std::vector<Copy> copies;
  bool was_reset = false;
};

VecWorld::VecWorld(const world::Scene& scene, std::size_t n, VecWorldOptions options)
    : impl_(std::make_unique<Impl>(scene, n, options)) {}
VecWorld::~VecWorld() = default;

std::size_t VecWorld::size() const { return impl_->copies.size(); }
std::size_t VecWorld::turtle_count() const { return impl_->turtles(); }
std::size_t VecWorld::thread_count() const { return impl_->pool.threads(); }
const ObsLayout& VecWorld::layout() const { return impl_->lay; }
std::size_t VecWorld::action_size() const { return impl_->action_size(); }
const VecWorldOptions& VecWorld::options() const { return impl_->options; }
const std::vector<std::string>& VecWorld::turtle_ids() const { return impl_->ids; }
double VecWorld::dt() const { return impl_->def.dt; }
std::vector<double> VecWorld::turtle_speeds() const {
  std::vector<double> out;
  for (const sim::TurtleDef& t : impl_->def.turtles) out.push_back(t.speed);
  return out;
}

void VecWorld::reset(std::uint64_t seed, std::span<float> obs) {
  Impl& m = *impl_;
  m.check_obs(obs);
  const std::size_t row = m.turtles() * m.lay.size;
  m.pool.run(m.copies.size(), [&](std::size_t i) {
    m.reset_copy(i, seed);
    m.observe(i, obs.data() + i * row);
  });
  m.was_reset = true;
}

void VecWorld::reset_one(std::size_t i, std::uint64_t seed, std::span<float> obs) {
  Impl& m = *impl_;
  m.check_obs(obs);
  if (i >= m.copies.size()) throw std::out_of_range("VecWorld::reset_one: copy " + std::to_string(i) + " of " + std::to_string(m.copies.size()));
  if (!m.was_reset) throw std::logic_error("VecWorld::reset_one: call reset first");
  m.reset_copy(i, seed);
  m.observe(i, obs.data() + i * m.turtles() * m.lay.size);
}

namespace {
template <class T>
void check_actions(const VecWorld& v, std::span<const T> actions, bool logo) {
  if ((v.options().actions == ActionKind::logo) != logo)
    throw std::invalid_argument(logo ? "VecWorld: integer (logo) actions given to a world made for continuous actions"
                                     : "VecWorld: continuous actions given to a world made for logo actions");
  const std::size_t need = v.size() * v.turtle_count() * v.action_size();
  if (actions.size() != need)
    throw std::invalid_argument("VecWorld: " + std::to_string(actions.size()) + " action values given; it needs " + std::to_string(v.size()) +
                                " copies x " + std::to_string(v.turtle_count()) + " turtles x " + std::to_string(v.action_size()) + " = " +
                                std::to_string(need));
}
}  // namespace

void VecWorld::step(std::span<const float> actions, std::span<float> obs, std::span<std::uint8_t> terminated,
                    std::span<std::uint8_t> truncated) {
  Impl& m = *impl_;
  if (!m.was_reset) throw std::logic_error("VecWorld::step: call reset first");
  check_actions(*this, actions, false);
  m.check_obs(obs);
  m.check_done_spans(terminated, truncated);
  const std::size_t row = m.turtles() * m.lay.size, arow = m.turtles() * 2;
  m.pool.run(m.copies.size(), [&](std::size_t i) {
    m.step_continuous(i, actions.data() + i * arow);
    m.observe(i, obs.data() + i * row);
    terminated[i] = m.copies[i].terminated;
    truncated[i] = m.copies[i].truncated;
  });
}

void VecWorld::step(std::span<const std::int32_t> actions, std::span<float> obs, std::span<std::uint8_t> terminated,
                    std::span<std::uint8_t> truncated) {
  Impl& m = *impl_;
  if (!m.was_reset) throw std::logic_error("VecWorld::step: call reset first");
  check_actions(*this, actions, true);
  m.check_obs(obs);
  m.check_done_spans(terminated, truncated);
  const std::size_t row = m.turtles() * m.lay.size, arow = m.turtles();
  m.pool.run(m.copies.size(), [&](std::size_t i) {
    m.step_logo(i, actions.data() + i * arow);
    m.observe(i, obs.data() + i * row);
    terminated[i] = m.copies[i].terminated;
    truncated[i] = m.copies[i].truncated;
  });
}

void VecWorld::sample_actions(std::span<float> out) {
  Impl& m = *impl_;
  if (m.options.actions == ActionKind::logo) throw std::invalid_argument("VecWorld: this world takes integer (logo) actions");
  if (out.size() != m.copies.size() * m.turtles() * 2) throw std::invalid_argument("VecWorld::sample_actions: wrong buffer size");
  const std::size_t row = m.turtles() * 2;
  for (std::size_t i = 0; i < m.copies.size(); ++i)
    for (std::size_t j = 0; j < row; ++j) out[i * row + j] = static_cast<float>(2.0 * uniform01(m.copies[i].actions_rng) - 1.0);
}

void VecWorld::sample_actions(std::span<std::int32_t> out) {
  Impl& m = *impl_;
  if (m.options.actions != ActionKind::logo) throw std::invalid_argument("VecWorld: this world takes continuous actions");
  if (out.size() != m.copies.size() * m.turtles()) throw std::invalid_argument("VecWorld::sample_actions: wrong buffer size");
  const std::size_t row = m.turtles();
  for (std::size_t i = 0; i < m.copies.size(); ++i)
    for (std::size_t j = 0; j < row; ++j) out[i * row + j] = static_cast<std::int32_t>(m.copies[i].actions_rng() % logo_action_count);
}

const sim::World& VecWorld::world(std::size_t i) const {
  if (i >= impl_->copies.size() || !impl_->copies[i].world) throw std::out_of_range("VecWorld::world: no copy " + std::to_string(i) + " (reset first)");
  return *impl_->copies[i].world;
}
std::uint64_t VecWorld::steps(std::size_t i) const { return impl_->copies.at(i).steps; }
std::uint64_t VecWorld::last_contacts(std::size_t i) const { return impl_->copies.at(i).contacts; }

}  // namespace turtlegas::learn
