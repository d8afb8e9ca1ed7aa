// SPDX-License-Identifier: MIT
#include "turtlegas/formats/observables.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "turtlegas/sim/mode_names.hpp"

namespace turtlegas::formats {
namespace {

/// Mean and block standard error of per-window values: the windows are taken as independent
/// samples (true once a window is much longer than the gas's correlation time).
nlohmann::json block(const std::vector<double>& x) {
  const double m = x.empty() ? 0.0 : std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
  double ss = 0.0;
  for (double v : x) ss += (v - m) * (v - m);
  const double n = static_cast<double>(x.size());
  const double err = x.size() > 1 ? std::sqrt(ss / (n * (n - 1.0))) : 0.0;
  return {{"mean", m}, {"error", err}};
}

}  // namespace

double henderson_z(double eta) { return (1.0 + eta * eta / 8.0) / ((1.0 - eta) * (1.0 - eta)); }
double henderson_contact(double eta) { return (1.0 - 7.0 * eta / 16.0) / ((1.0 - eta) * (1.0 - eta)); }
double carnahan_starling_z(double eta) {
  return (1.0 + eta + eta * eta - eta * eta * eta) / ((1.0 - eta) * (1.0 - eta) * (1.0 - eta));
}
double carnahan_starling_contact(double eta) { return (1.0 - eta / 2.0) / ((1.0 - eta) * (1.0 - eta) * (1.0 - eta)); }
double klm_z(double eta) {
  // Kolafa, Labik and Malijevsky, Phys. Chem. Chem. Phys. 6, 2335 (2004): CS with its eta^3 term
  // replaced by -(2/3)(eta^3 + eta^4).
  return (1.0 + eta + eta * eta - 2.0 / 3.0 * (eta * eta * eta + eta * eta * eta * eta)) /
         ((1.0 - eta) * (1.0 - eta) * (1.0 - eta));
}

std::string check_observe(const ObserveOptions& o, double start, double until) {
  if (!(o.from >= start) || !(o.from < until))
    return "--observe-from must lie in [" + std::to_string(start) + ", " + std::to_string(until) +
           ") s, the run's start and --until; give a time before --until";
  const double window = o.window > 0.0 ? o.window : (until - o.from) / 10.0;
  if (!(o.window >= 0.0) || !std::isfinite(o.window)) return "--observe-window must be a positive number of seconds";
  if (o.from + window > until)
    return "--observe-window " + std::to_string(window) + " s does not fit between --observe-from and --until; give a "
           "shorter window or a later --until";
  if (o.samples < 1) return "--observe-samples must be at least 1";
  if (o.axis != 'x' && o.axis != 'y' && o.axis != 'z') return "--observe-axis must be x or y (or z in 3-D)";
  if (o.profile_bins < 1 || o.speed_bins < 1) return "--observe-bins must be at least 1";
  if (o.rdf_bins < 1) return "--observe-rdf-bins must be at least 1";
  if (!(o.rdf_max >= 0.0) || !std::isfinite(o.rdf_max)) return "--observe-rdf-max must be a distance >= 0 (0: automatic)";
  return {};
}

Observer::Observer(sim::World& world, const sim::WorldDef& def, ObserveOptions options, double until)
    : world_(&world),
      opt_(options),
      name_(def.name),
      boundary_(def.arena.boundary),
      width_(def.arena.width),
      height_(def.arena.height) {
  size_ = {width_, height_, 0.0};
  if (opt_.window <= 0.0) opt_.window = (until - opt_.from) / 10.0;
  last_window_ = static_cast<std::size_t>(std::floor((until - opt_.from) / opt_.window));
  for (const sim::WallDef& w : world.walls()) {
    wall_length_.push_back(norm(w.to - w.from));
    wall_id_.push_back(w.id);
  }
  init_species();
  world.set_impulse_log(&impulses_);
}

Observer::Observer(sim::World3& world, const sim::World3Def& def, std::string name, ObserveOptions options,
                   double until, std::vector<std::string> wall_ids)
    : world3_(&world),
      dims_(3),
      size_(def.size),
      opt_(options),
      name_(std::move(name)),
      boundary_(def.boundary == sim::Boundary3::periodic ? sim::Boundary::periodic
                : def.boundary == sim::Boundary3::walls  ? sim::Boundary::walls
                                                         : sim::Boundary::none),
      width_(def.size.x),
      height_(def.size.y) {
  if (opt_.window <= 0.0) opt_.window = (until - opt_.from) / 10.0;
  last_window_ = static_cast<std::size_t>(std::floor((until - opt_.from) / opt_.window));
  for (const sim::Sphere3Def& s : def.spheres) mass3_.push_back(s.mass), radius3_.push_back(s.radius);
  for (std::size_t k = 0; k < world.wall_count(); ++k) {
    wall_length_.push_back(world.wall_area(k));
    wall_id_.push_back(k < wall_ids.size() ? wall_ids[k] : "wall-" + std::to_string(k));
  }
  init_species();
  take_push3(nullptr);
  virial3_ = world.virial_sum();
}

void Observer::take_push3(Window* into) {
  push3_.resize(wall_length_.size(), 0.0);
  for (std::size_t k = 0; k < push3_.size(); ++k) {
    const double now = world3_->wall_push(k);
    if (into) into->wall_push[k] += now - push3_[k];
    push3_[k] = now;
  }
}

void Observer::init_species() {
  double r_big = 0.0;
  for (std::size_t i = 0; i < count(); ++i) {
    ++masses_[mass(i)];
    const double r = radius(i), m = mass(i);
    r_big = std::max(r_big, r);
    std::size_t s = 0;
    while (s < species_.size() && !(species_[s].radius == r && species_[s].mass == m)) ++s;
    if (s == species_.size()) species_.push_back({r, m, 0});
    ++species_[s].count;
    species_of_.push_back(s);
  }
  if (species_.empty()) species_.push_back({1.0, 1.0, 0});
  // g(r) reaches 5 of the largest diameters unless told otherwise, and never beyond what the arena
  // allows: half the shortest side (the nearest image) when periodic, the centres' room behind walls.
  double side = std::min(size_.x, size_.y);
  if (dims_ == 3) side = std::min(side, size_.z);
  const double room = boundary_ == sim::Boundary::periodic ? 0.5 * side
                      : boundary_ == sim::Boundary::walls  ? side - 2.0 * r_big
                                                           : side;
  rdf_max_ = std::min(opt_.rdf_max > 0.0 ? opt_.rdf_max : 10.0 * std::max(r_big, 1e-300), room);
}

std::size_t Observer::count() const { return world3_ ? world3_->sphere_count() : world_->ball_count(); }
bool Observer::alive(std::size_t i) const { return world3_ ? world3_->alive(i) : world_->ball(i).alive; }
sim::Vec3 Observer::pos(std::size_t i) const {
  if (world3_) return world3_->position(i);
  const sim::Vec2 p = world_->ball(i).pos;
  return {p.x, p.y, 0.0};
}
sim::Vec3 Observer::vel(std::size_t i) const {
  if (world3_) return world3_->velocity(i);
  const sim::Vec2 v = world_->ball(i).vel;
  return {v.x, v.y, 0.0};
}
double Observer::mass(std::size_t i) const { return world3_ ? mass3_[i] : world_->mass(i); }
double Observer::radius(std::size_t i) const { return world3_ ? radius3_[i] : world_->radius(i); }
double Observer::now() const { return world3_ ? world3_->time() : world_->time(); }
void Observer::step_to(double t) {
  if (world3_) world3_->advance_to(t, &events3_);
  else world_->advance_to(t);
}

Observer::~Observer() { detach(); }

void Observer::detach() {
  if (forward && !impulses_.empty()) forward(impulses_);
  impulses_.clear();
  if (world_) world_->set_impulse_log(nullptr);
  world_ = nullptr;
  world3_ = nullptr;
}

Observer::Window Observer::fresh(double t0) const {
  Window w;
  w.t0 = t0;
  w.t1 = t0 + opt_.window;
  w.wall_push.assign(wall_length_.size(), 0.0);
  w.speeds.assign(static_cast<std::size_t>(opt_.speed_bins), 0.0);
  w.profile.assign(static_cast<std::size_t>(opt_.profile_bins), 0.0);
  const std::size_t S = species_.size();
  w.kT_species.assign(S, 0.0);
  w.pair_norm.assign(S * (S + 1) / 2, 0.0);
  w.pair_counts.assign(w.pair_norm.size() * static_cast<std::size_t>(opt_.rdf_bins), 0.0);
  return w;
}

void Observer::advance_to(double t) {
  const auto attached = [this] { return world_ != nullptr || world3_ != nullptr; };
  // While observing a periodic gas, the world stops often enough to unwrap its coordinates.
  auto go = [this](double target) {
    target = std::max(target, now());
    if (started_ && boundary_ == sim::Boundary::periodic && done_.size() < last_window_) {
      while (now() < target) {
        step_to(std::min(target, now() + unwrap_step()));
        unwrap();
      }
    } else {
      step_to(target);
    }
  };
  while (attached() && done_.size() < last_window_) {
    // The next stop: the start of the observation, then each sample of the current window.
    const double k = static_cast<double>(done_.size());
    const double stop = !started_ ? opt_.from
                                 : opt_.from + opt_.window * (k + static_cast<double>(next_sample_) / opt_.samples);
    if (stop > t) break;
    go(stop);
    if (!started_) {
      started_ = true;
      if (forward) forward(impulses_);
      impulses_.clear();  // before the observation
      events3_.clear();
      if (world3_) virial3_ = world3_->virial_sum(), take_push3(nullptr);
      double v2 = 0.0, n = 0.0;
      for (std::size_t i = 0; i < count(); ++i)
        if (alive(i)) v2 += dot(vel(i), vel(i)), n += 1.0;
      speed_max_ = n > 0.0 && v2 > 0.0 ? 4.0 * std::sqrt(v2 / n) : 1.0;
      current_ = fresh(opt_.from);
      next_sample_ = 1;
      start_motion();
      continue;
    }
    take_impulses();
    sample();
    if (++next_sample_ > static_cast<std::size_t>(opt_.samples)) {
      close_motion(current_);
      done_.push_back(std::move(current_));
      current_ = fresh(opt_.from + opt_.window * (k + 1.0));
      next_sample_ = 1;
    }
  }
  if (attached() && now() < t) go(t);
  if (attached() && done_.size() >= last_window_) {  // after the last window
    if (forward) forward(impulses_);
    impulses_.clear();
    events3_.clear();
  }
}

void Observer::take_impulses() {
  if (world3_) {
    // The 3-D engine reports its events and the running virial sum (sum of r . dp over pairs).
    for (const sim::Event3& e : events3_) {
      if (e.kind == sim::Event3Kind::ball_ball) ++current_.ball_ball;
      else if (e.kind != sim::Event3Kind::exit) ++current_.ball_wall;
    }
    events3_.clear();
    current_.virial += world3_->virial_sum() - virial3_;
    virial3_ = world3_->virial_sum();
    take_push3(&current_);
    return;
  }
  if (forward) forward(impulses_);
  for (const sim::Impulse& c : impulses_) {
    if (c.kind == sim::EventKind::ball_ball) {
      ++current_.ball_ball;
      current_.virial += dot(c.r, c.dp);
    } else {
      ++current_.ball_wall;
      const double len = norm(c.r);
      if (len > 0.0 && c.b < current_.wall_push.size()) current_.wall_push[c.b] += dot(c.dp, c.r) / len;
    }
  }
  impulses_.clear();
}

void Observer::sample() {
  double n = 0.0, m_sum = 0.0;
  sim::Vec3 p{};
  for (std::size_t i = 0; i < count(); ++i) {
    if (!alive(i)) continue;
    n += 1.0;
    m_sum += mass(i);
    p += mass(i) * vel(i);
  }
  if (n == 0.0) return;
  // Periodic arenas conserve momentum: the temperature is of the velocities about the centre of
  // mass's, over d(N - 1) degrees of freedom. Walls take momentum; there it is d N, in the lab.
  const bool periodic = boundary_ == sim::Boundary::periodic;
  const sim::Vec3 vc = periodic ? sim::Vec3{p.x / m_sum, p.y / m_sum, p.z / m_sum} : sim::Vec3{};
  const double d = dims_;
  const double dof = periodic ? d * (n - 1.0) : d * n;
  double twice_ke = 0.0, speed = 0.0;
  std::vector<double> twice_ke_s(species_.size(), 0.0), n_s(species_.size(), 0.0);
  const int ax = opt_.axis == 'x' ? 0 : opt_.axis == 'y' ? 1 : 2;
  const double extent = size_[ax];
  for (std::size_t i = 0; i < count(); ++i) {
    if (!alive(i)) continue;
    const sim::Vec3 v = vel(i), u = v - vc;
    twice_ke += mass(i) * dot(u, u);
    twice_ke_s[species_of_[i]] += mass(i) * dot(u, u);
    n_s[species_of_[i]] += 1.0;
    const double s = norm(v);
    speed += s;
    const double sb = s / speed_max_ * opt_.speed_bins;
    if (sb < opt_.speed_bins) current_.speeds[static_cast<std::size_t>(sb)] += 1.0;
    else current_.speed_overflow += 1.0;
    double c = pos(i)[ax];
    if (periodic) c -= extent * std::floor(c / extent);
    const double pb = c / extent * opt_.profile_bins;
    if (pb >= 0.0 && pb < opt_.profile_bins) current_.profile[static_cast<std::size_t>(pb)] += 1.0;
  }
  current_.kT += dof > 0.0 ? twice_ke / dof : 0.0;
  current_.kinetic += twice_ke / 2.0;
  current_.mean_speed += speed / n;
  current_.balls += n;
  for (std::size_t k = 0; k < species_.size(); ++k)
    current_.kT_species[k] += n_s[k] > 0.0 ? twice_ke_s[k] / (d * n_s[k]) : 0.0;
  ++current_.samples;
  sample_pairs();
  sample_motion();
}

nlohmann::json Observer::result() const {
  const bool periodic = boundary_ == sim::Boundary::periodic;
  const double area = volume();  // the area in 2-D, the volume in 3-D
  const double d = dims_;
  const int ax = opt_.axis == 'x' ? 0 : opt_.axis == 'y' ? 1 : 2;
  const double extent = size_[ax];
  const double across = area / extent;
  double total_length = 0.0;
  for (double l : wall_length_) total_length += l;
  std::vector<double> kT, speed, rate, wall_rate, mfp, p_walls, p_virial, z_virial, p_canonical, z_canonical, density;
  std::vector<std::vector<double>> per_wall(wall_length_.size());
  nlohmann::json windows = nlohmann::json::array();
  for (const Window& w : done_) {
    const double s = std::max(w.samples, 1);
    const double n = w.balls / s, T = w.kT / s, dt = w.t1 - w.t0;
    const double v = w.mean_speed / s;
    const double nu = n > 0.0 ? 2.0 * static_cast<double>(w.ball_ball) / (n * dt) : 0.0;
    kT.push_back(T);
    speed.push_back(v);
    rate.push_back(nu);
    wall_rate.push_back(n > 0.0 ? static_cast<double>(w.ball_wall) / (n * dt) : 0.0);
    mfp.push_back(nu > 0.0 ? v / nu : INFINITY);
    density.push_back(n / area);
    double push = 0.0;
    for (std::size_t k = 0; k < w.wall_push.size(); ++k) {
      push += w.wall_push[k];
      per_wall[k].push_back(wall_length_[k] > 0.0 ? w.wall_push[k] / (wall_length_[k] * dt) : 0.0);
    }
    p_walls.push_back(total_length > 0.0 ? push / (total_length * dt) : 0.0);
    nlohmann::json row = {{"t0", w.t0}, {"t1", w.t1}, {"kT", T}, {"mean_speed", v}, {"collision_rate", nu},
                          {"wall_collision_rate", wall_rate.back()}, {"mean_free_path", mfp.back()},
                          {"pressure_walls", p_walls.back()}};
    if (periodic) {
      // The virial theorem in two dimensions: P A = K + (1/2) <sum r_ij . F_ij>, K the kinetic
      // energy about the centre of mass ((N - 1) kT: a periodic gas's drift exerts no pressure),
      // the time average of the forces being the collisions' sum of r . dp over the window.
      // In d dimensions P V = (2/d) K + (1/d) <sum r_ij . F_ij>.
      const double P = (2.0 * w.kinetic / s / d + w.virial / (d * dt)) / area;
      p_virial.push_back(P);
      z_virial.push_back(n * T > 0.0 ? P * area / (n * T) : 0.0);
      // The canonical (Monte Carlo, NVT) pressure of the same N and area: a momentum-conserving run
      // has d(N - 1) kinetic degrees of freedom, a canonical one d N, so its ideal part is N kT / A
      // where ours is (N - 1) kT / A. The collisional part is the same at the same kT: hard discs'
      // configurations are equally likely in both ensembles, and at fixed total momentum the pair's
      // relative velocity still has <(v_i - v_j)_a^2> = kT / m_red exactly (docs/physics.md, "Gas
      // observables"). So P_canonical = P + kT / A and Z_canonical = Z + 1 / N.
      p_canonical.push_back(P + T / area);
      z_canonical.push_back(n > 0.0 ? z_virial.back() + 1.0 / n : 0.0);
      row["pressure_virial"] = P;
      row["Z_virial"] = z_virial.back();
      row["pressure_canonical"] = p_canonical.back();
      row["Z_canonical"] = z_canonical.back();
    }
    windows.push_back(row);
  }
  nlohmann::json summary = {{"kT", block(kT)},
                            {"mean_speed", block(speed)},
                            {"collision_rate", block(rate)},
                            {"wall_collision_rate", block(wall_rate)},
                            {"mean_free_path", block(mfp)},
                            {"number_density", block(density)},
                            {"pressure_walls", block(p_walls)}};
  if (periodic) {
    summary["pressure_virial"] = block(p_virial);
    summary["Z_virial"] = block(z_virial);
    summary["pressure_canonical"] = block(p_canonical);
    summary["Z_canonical"] = block(z_canonical);
  }
  // Histograms: per window, normalised, then block-averaged bin by bin.
  const double bw = speed_max_ / opt_.speed_bins;
  nlohmann::json edges = nlohmann::json::array(), dens = nlohmann::json::array(), errs = nlohmann::json::array(),
                 rayleigh = nlohmann::json::array();
  const double T = block(kT)["mean"].get<double>();
  double n_balls = 0.0;
  for (const auto& [m, c] : masses_) n_balls += static_cast<double>(c);
  std::vector<double> overflow;
  for (const Window& w : done_) overflow.push_back(w.speed_overflow / std::max(w.balls, 1.0));
  for (int b = 0; b <= opt_.speed_bins; ++b) edges.push_back(b * bw);
  for (int b = 0; b < opt_.speed_bins; ++b) {
    std::vector<double> f;
    for (const Window& w : done_) f.push_back(w.speeds[static_cast<std::size_t>(b)] / (std::max(w.balls, 1.0) * bw));
    const nlohmann::json s = block(f);
    dens.push_back(s["mean"]);
    errs.push_back(s["error"]);
    // The Maxwell-Boltzmann speed distribution of each mass, weighted by how many balls have it,
    // averaged over the bin (its integral is exact): in 2-D m v/kT exp(-m v^2/(2 kT)), whose
    // integral is 1 - exp(-m v^2/(2 kT)); in 3-D erf(x/sqrt 2) - sqrt(2/pi) x exp(-x^2/2), x = v sqrt(m/kT).
    double frac = 0.0;
    const double lo = b * bw, hi = (b + 1) * bw;
    for (const auto& [m, c] : masses_)
      if (T > 0.0 && dims_ == 2)
        frac += static_cast<double>(c) / n_balls *
                (std::exp(-m * lo * lo / (2.0 * T)) - std::exp(-m * hi * hi / (2.0 * T)));
      else if (T > 0.0) {
        auto cdf = [&, mass = m](double v) {  // (a structured binding is captured by copy: clang 14)
          const double x = v * std::sqrt(mass / T);
          return std::erf(x / std::sqrt(2.0)) - std::sqrt(2.0 / 3.14159265358979323846) * x * std::exp(-x * x / 2.0);
        };
        frac += static_cast<double>(c) / n_balls * (cdf(hi) - cdf(lo));
      }
    rayleigh.push_back(frac / bw);
  }
  nlohmann::json speeds = {{"edges", edges}, {"density", dens}, {"error", errs}, {dims_ == 3 ? "maxwell" : "rayleigh", rayleigh},
                           {"overflow", block(overflow)}};
  const double pw = extent / opt_.profile_bins;
  nlohmann::json pedges = nlohmann::json::array(), pdens = nlohmann::json::array(), perrs = nlohmann::json::array();
  for (int b = 0; b <= opt_.profile_bins; ++b) pedges.push_back(b * pw);
  for (int b = 0; b < opt_.profile_bins; ++b) {
    std::vector<double> f;
    for (const Window& w : done_)
      f.push_back(w.profile[static_cast<std::size_t>(b)] / (std::max(w.samples, 1) * pw * across));
    const nlohmann::json s = block(f);
    pdens.push_back(s["mean"]);
    perrs.push_back(s["error"]);
  }
  nlohmann::json walls = nlohmann::json::array();
  for (std::size_t k = 0; k < wall_length_.size(); ++k)
    walls.push_back({{"id", wall_id_[k]}, {dims_ == 3 ? "area" : "length", wall_length_[k]}, {"pressure", block(per_wall[k])}});
  nlohmann::json out = {{"format", "turtlegas-observables/1"},
          {"name", name_},
          {"boundary", std::string(sim::to_string(boundary_))},
          {dims_ == 3 ? "volume" : "area", area},
          {"from", opt_.from},
          {"window", opt_.window},
          {"samples_per_window", opt_.samples},
          {"windows", done_.size()},
          {"summary", summary},
          {"per_window", windows},
          {"speed_histogram", speeds},
          {"density_profile", {{"axis", std::string(1, opt_.axis)}, {"edges", pedges}, {"density", pdens}, {"error", perrs}}},
          {"walls", walls}};
  if (dims_ == 3) out["dimensions"] = 3;
  pair_results(out, out["summary"]);
  motion_results(out, out["summary"]);
  return out;
}

}  // namespace turtlegas::formats
