// SPDX-License-Identifier: MIT
// Gas observables (`turtlegas run --observe F.json`, docs/physics.md "Gas observables"):
// temperature, wall pressure from collision impulses, virial pressure (periodic arenas), collision
// rates, mean free path, the speed histogram beside the 2-D Maxwell-Boltzmann (Rayleigh)
// distribution and a density profile, over consecutive time windows with block-average error bars;
// the radial distribution function g(r) with its contact values, the mean-squared displacement of
// unwrapped coordinates and the velocity autocorrelation function with the diffusion coefficient
// from each (Einstein and Green-Kubo), per species (balls of one radius and mass) for mixtures.
// Computed from what the engine reports: the impulse of every collision (World::set_impulse_log)
// and state samples taken at fixed times. The physics does not depend on where a run is cut, so
// stopping at the sample times changes nothing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world3d.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::formats {

struct ObserveOptions {
  double from = 0.0;       ///< seconds: what happens before is not observed (equilibration)
  double window = 0.0;     ///< seconds per window (block); 0: a tenth of (until - from)
  int samples = 20;        ///< state samples per window, evenly spaced, the last at its end
  char axis = 'y';         ///< the density profile's axis, 'x' or 'y' ('z' too in 3-D)
  int profile_bins = 20;   ///< across the arena's extent along the axis
  int speed_bins = 40;     ///< from 0 to 4 times the rms speed at `from`
  int rdf_bins = 200;      ///< bins of g(r), from 0 to rdf_max
  double rdf_max = 0.0;    ///< world units; 0: 5 largest diameters, at most what the arena allows
};

/// Checks the options against a run to `until` from `start`; returns an empty string or what is
/// wrong (naming the option and the fix).
std::string check_observe(const ObserveOptions& o, double start, double until);

class Observer {
 public:
  /// For a run of `world` (built from `def`) to `until`. Installs its impulse log in the world
  /// (World::set_impulse_log); the world must outlive the observer or be detached first.
  Observer(sim::World& world, const sim::WorldDef& def, ObserveOptions options, double until);
  /// For a run of the 3-D gas `world` (built from `def`, named `name`) to `until`: the same
  /// measurements in three dimensions (docs/observables.md, "3-D"), the walls' pressure per unit
  /// area. wall_ids name the world's walls (World3::wall_count() of them; empty: "wall-k"). The
  /// world must outlive the observer.
  Observer(sim::World3& world, const sim::World3Def& def, std::string name, ObserveOptions options, double until,
           std::vector<std::string> wall_ids = {});
  Observer(const Observer&) = delete;
  Observer& operator=(const Observer&) = delete;
  ~Observer();

  /// Advances the world to t (>= its time), stopping at every sample time on the way.
  void advance_to(double t);
  /// The observer's world no longer reports impulses.
  void detach();
  /// Whole windows observed so far.
  std::size_t windows() const { return done_.size(); }
  /// Called with every batch of impulses before the observer drops it (another consumer of the
  /// world's one impulse log: the SVG's ball trails).
  std::function<void(const std::vector<sim::Impulse>&)> forward;
  /// The measurements (format turtlegas-observables/1, docs/physics.md).
  nlohmann::json result() const;

 private:
  /// Balls of one radius and mass, in the order they first appear in the world.
  struct Species {
    double radius = 0.0, mass = 0.0;
    std::size_t count = 0;
  };
  struct Window {
    double t0 = 0.0, t1 = 0.0;
    std::uint64_t ball_ball = 0, ball_wall = 0;
    double virial = 0.0;            ///< sum of r . dp over ball-ball collisions
    std::vector<double> wall_push;  ///< per wall: normal impulse received
    int samples = 0;
    double kT = 0.0, kinetic = 0.0, mean_speed = 0.0, balls = 0.0;  ///< sums over samples
    std::vector<double> speeds, profile;             ///< counts over samples
    double speed_overflow = 0.0;
    std::vector<double> kT_species;                  ///< sums over samples, per species
    std::vector<double> pair_counts;                 ///< per species pair (a <= b) and r bin
    std::vector<double> pair_norm;                   ///< per species pair: sum over samples of pairs
    std::vector<double> msd, vacf;                   ///< per lag 0..samples, then per species and lag
  };
  void sample_pairs();
  void start_motion();
  void unwrap();
  void sample_motion();
  void close_motion(Window& w);
  double unwrap_step() const;
  std::size_t pair_index(std::size_t a, std::size_t b) const;
  double expected_pairs(std::size_t a, std::size_t b, double r0, double r1) const;
  void pair_results(nlohmann::json& out, nlohmann::json& summary) const;
  void motion_results(nlohmann::json& out, nlohmann::json& summary) const;
  void take_impulses();
  // The gas read through one interface in 2 or 3 dimensions (a 2-D ball has z = 0).
  std::size_t count() const;
  bool alive(std::size_t i) const;
  sim::Vec3 pos(std::size_t i) const;
  sim::Vec3 vel(std::size_t i) const;
  double mass(std::size_t i) const;
  double radius(std::size_t i) const;
  double now() const;
  void step_to(double t);
  double volume() const { return dims_ == 3 ? size_.x * size_.y * size_.z : size_.x * size_.y; }
  void init_species();
  /// Adds the 3-D walls' push since the last take to `into` (if given) and remembers it.
  void take_push3(Window* into);
  void sample();
  Window fresh(double t0) const;

  sim::World* world_ = nullptr;
  sim::World3* world3_ = nullptr;
  int dims_ = 2;
  sim::Vec3 size_;                   ///< width, height and (3-D) depth
  double virial3_ = 0.0;             ///< the 3-D world's virial_sum at the last take
  std::vector<double> push3_;        ///< the 3-D world's wall_push per wall at the last take
  std::vector<sim::Event3> events3_;  ///< the 3-D world's events since the last take
  std::vector<double> mass3_, radius3_;  ///< per 3-D sphere, from its def
  ObserveOptions opt_;
  std::string name_;
  sim::Boundary boundary_;
  double width_ = 0.0, height_ = 0.0;
  double speed_max_ = 0.0;
  bool started_ = false;
  std::vector<double> wall_length_;  ///< per wall: its length (2-D) or area (3-D)
  std::vector<std::string> wall_id_;
  std::map<double, std::size_t> masses_;  ///< the balls' masses and how many have each
  std::vector<Species> species_;
  std::vector<std::size_t> species_of_;   ///< per ball
  double rdf_max_ = 0.0;
  std::vector<sim::Vec3> unwrapped_, last_pos_;  ///< since `from`; positions at the last unwrap
  std::vector<sim::Vec3> images_;  ///< per ball: whole periods crossed since `from` (integers)
  /// Per window: frames 0..samples of unwrapped positions and velocities (NaN x: not alive).
  std::vector<std::vector<sim::Vec3>> frame_pos_, frame_vel_;
  std::vector<sim::Impulse> impulses_;
  Window current_;
  std::vector<Window> done_;
  std::size_t next_sample_ = 1;  ///< of the current window, 1..samples
  std::size_t last_window_ = 0;  ///< windows that fit before until
};

/// Henderson's equation of state of hard discs, Z = (1 + eta^2/8) / (1 - eta)^2, and its contact
/// value g(sigma) = (1 - 7 eta/16) / (1 - eta)^2 (Z = 1 + 2 eta g), eta the area fraction.
double henderson_z(double eta);
double henderson_contact(double eta);
/// Carnahan-Starling's equation of state of hard spheres, Z = (1 + eta + eta^2 - eta^3) / (1 - eta)^3,
/// and its contact value g(sigma) = (1 - eta/2) / (1 - eta)^3 (Z = 1 + 4 eta g), eta the volume fraction.
double carnahan_starling_z(double eta);
double carnahan_starling_contact(double eta);
/// Kolafa, Labik and Malijevsky's (2004) equation of state of hard spheres, closer than
/// Carnahan-Starling to simulations at eta >= 0.45: Z_CS + eta^2 (... ) terms (observables.cpp).
double klm_z(double eta);

}  // namespace turtlegas::formats
