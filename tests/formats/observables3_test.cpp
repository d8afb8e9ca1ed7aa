// SPDX-License-Identifier: MIT
// The Observer of a 3-D gas (docs/observables.md, "3-D"): periodic hard spheres from an fcc start,
// their pressure against Carnahan-Starling (and Kolafa-Labik-Malijevsky at eta 0.45), the contact
// value of g(r) against the virial's, the collision rate against Enskog's, the speed histogram
// against Maxwell's and the temperature against the conserved energy.
#include <catch2/catch.hpp>

#include <cmath>

#include "turtlegas/formats/observables.hpp"
#include "turtlegas/sim/gas3d.hpp"

using namespace turtlegas;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Measured {
  double z, z_err, g, g_err, rate, rate_err, kT, n, d_msd, d_gk;
  nlohmann::json out;
};

/// 4 k^3 spheres of diameter 1 at eta: melted for 30 collisions per sphere, then 8 windows of
/// about 25 collisions per sphere each.
Measured observe(int k, double eta, std::uint64_t seed) {
  sim::World3 w(sim::fcc_gas3(k, eta, seed));
  const double n = static_cast<double>(w.sphere_count());
  while (w.collisions() < 30 * n) w.advance_to(w.time() + 0.05);
  const double from = w.time();
  const double rate = 2.0 * static_cast<double>(w.collisions()) / (n * from);  // a guess for the window's length
  formats::ObserveOptions o;
  o.from = from;
  o.window = 25.0 / rate;
  o.samples = 50;  // half a collision time apart: the VACF's trapezoid is then within 2 %
  const double until = from + 8 * o.window;
  formats::Observer obs(w, sim::fcc_gas3(k, eta, seed), "fcc", o, until);
  obs.advance_to(until);
  Measured m;
  m.out = obs.result();
  const auto& s = m.out["summary"];
  m.z = s["Z_canonical"]["mean"], m.z_err = s["Z_canonical"]["error"];
  m.g = s["g_contact"]["mean"], m.g_err = s["g_contact"]["error"];
  m.rate = s["collision_rate"]["mean"], m.rate_err = s["collision_rate"]["error"];
  m.kT = s["kT"]["mean"], m.n = s["number_density"]["mean"];
  m.d_msd = s["D_msd"]["mean"], m.d_gk = s["D_green_kubo"]["mean"];
  // The temperature is the conserved kinetic energy over 3(N - 1) degrees of freedom.
  CHECK(std::abs(m.kT - 2.0 * w.kinetic_energy() / (3.0 * (n - 1.0))) < 1e-9);
  return m;
}

}  // namespace

TEST_CASE("3-D observables: pressure, contact value and collision rate at eta 0.1 to 0.4") {
  for (double eta : {0.1, 0.2, 0.3, 0.4}) {
    const Measured m = observe(5, eta, 21);
    const double cs = formats::carnahan_starling_z(eta), chi = formats::carnahan_starling_contact(eta);
    // Enskog: a sphere meets others at the rate n sigma^2 chi <|g . u|> over the half sphere of
    // approach, 4 n sigma^2 chi sqrt(pi kT / m) for sigma = 1, m = 1 (docs/observables.md).
    const double enskog = 4.0 * m.n * chi * std::sqrt(kPi * m.kT);
    INFO("eta " << eta << ": Z " << m.z << " +- " << m.z_err << " (CS " << cs << "); g(sigma) " << m.g << " +- "
                << m.g_err << " (CS " << chi << "); rate " << m.rate << " +- " << m.rate_err << " (Enskog " << enskog
                << "); D " << m.d_msd << " / " << m.d_gk);
    // Within 4 standard errors and 2 %: an ideal-gas term in the wrong dimension (2/2 K instead
    // of 2/3 K) is 10 % off at eta 0.4, a missing 1/d in the virial 50 %.
    CHECK(std::abs(m.z - cs) < std::max(4.0 * m.z_err, 0.005 * cs));
    CHECK(std::abs(m.z - cs) < 0.02 * cs);
    // g(sigma+) from the histogram's straight-line extrapolation over 0.1 sigma: within 3 % of CS's
    // up to eta 0.3; at 0.4, where g falls steeply and curves, the line undershoots by about 5 %
    // (measured 3.49 against 3.70), so 7 %. A 2-D shell normalisation would be off by a factor ~ r.
    CHECK(std::abs(m.g - chi) < std::max(4.0 * m.g_err, (eta < 0.35 ? 0.03 : 0.07) * chi));
    // The collision rate: Enskog's with CS's chi is the exact rate at the true contact value.
    CHECK(std::abs(m.rate - enskog) < std::max(4.0 * m.rate_err, 0.02 * enskog));
    // Einstein and Green-Kubo agree with each other (d = 3 in both: a 2-D formula is 33 % off).
    CHECK(std::abs(m.d_msd - m.d_gk) < 0.1 * m.d_msd);
    // Enskog's D = 3 / (8 n sigma^2 chi) sqrt(kT / (pi m)); the true D is within 15 % of it up to
    // eta 0.2; beyond, correlated collisions raise it (Alder, Gass and Wainwright: 1.2 at eta 0.3).
    const double d_enskog = 3.0 / (8.0 * m.n * chi) * std::sqrt(m.kT / kPi);
    UNSCOPED_INFO("D_Enskog " << d_enskog);
    if (eta < 0.25) CHECK(std::abs(m.d_msd - d_enskog) < 0.15 * d_enskog);
    // The speed histogram follows Maxwell's 3-D law bin by bin.
    const auto& h = m.out["speed_histogram"];
    double worst = 0.0;
    for (std::size_t b = 0; b < h["density"].size(); ++b)
      worst = std::max(worst, std::abs(h["density"][b].get<double>() - h["maxwell"][b].get<double>()) /
                                  (5.0 * h["error"][b].get<double>() + 0.02 * 0.6));
    CHECK(worst < 1.0);
  }
}

TEST_CASE("3-D observables: at eta 0.45 the pressure is Kolafa-Labik-Malijevsky's (and Carnahan-Starling's)") {
  const double eta = 0.45;
  const Measured m = observe(5, eta, 23);
  const double klm = formats::klm_z(eta), cs = formats::carnahan_starling_z(eta);
  INFO("Z " << m.z << " +- " << m.z_err << ", KLM " << klm << ", CS " << cs);
  // KLM and CS differ by 0.2 % here, less than this run's error bar: both are held to 4 errors and 2 %.
  CHECK(std::abs(m.z - klm) < std::max(4.0 * m.z_err, 0.005 * klm));
  CHECK(std::abs(m.z - klm) < 0.02 * klm);
  CHECK(std::abs(m.z - cs) < 0.02 * cs);
}

TEST_CASE("3-D walls: the push one sphere gives each face is m v_n^2 / (L - 2r) a second") {
  // One sphere in a closed box meets nothing but the six faces: between two faces normal to x it
  // goes and returns in 2 (L_x - 2r) / |v_x|, giving each 2 m |v_x|, so each receives
  // m v_x^2 / (L_x - 2r) a second, to within one bounce over the run.
  sim::World3Def def;
  def.size = {20.0, 30.0, 40.0};
  def.boundary = sim::Boundary3::walls;
  sim::Sphere3Def s;
  s.pos = {7.0, 11.0, 13.0};
  s.vel = {3.0, -2.0, 1.25};
  s.radius = 1.0;
  s.mass = 2.5;
  def.spheres.push_back(s);
  sim::World3 w(def);
  const double T = 1000.0;
  w.advance_to(T);
  REQUIRE(w.wall_count() == 6);
  const double v[3] = {3.0, 2.0, 1.25}, L[3] = {20.0, 30.0, 40.0};
  const double areas[3] = {30.0 * 40.0, 20.0 * 40.0, 20.0 * 30.0};
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) {
      const std::size_t k = static_cast<std::size_t>(2 * a + side);
      INFO("wall " << k);
      CHECK(std::abs(w.wall_area(k) - areas[a]) < 1e-9 * areas[a]);
      const double expected = s.mass * v[a] * v[a] / (L[a] - 2.0) * T, one_bounce = 2.0 * s.mass * v[a];
      CHECK(std::abs(w.wall_push(k) - expected) <= one_bounce * (1.0 + 1e-9));
    }
}

TEST_CASE("3-D walls: a polygon's area, and an inelastic wall receives (1 + e) m v_n") {
  sim::World3Def def;
  def.size = {10.0, 10.0, 10.0};
  def.boundary = sim::Boundary3::none;
  sim::Wall3Def tri;
  tri.corners = {{1.0, 1.0, 2.0}, {5.0, 1.0, 2.0}, {1.0, 4.0, 2.0}};  // legs 4 and 3: area 6
  tri.restitution = 0.5;
  def.walls.push_back(tri);
  sim::Sphere3Def s;
  s.pos = {2.0, 2.0, 6.0};
  s.vel = {0.0, 0.0, -2.0};  // meets the face once, at z = 2 + r
  s.radius = 0.5;
  s.mass = 3.0;
  def.spheres.push_back(s);
  sim::World3 w(def);
  CHECK(std::abs(w.wall_area(0) - 6.0) < 1e-12);
  w.advance_to(10.0);
  CHECK(std::abs(w.wall_push(0) - (1.0 + 0.5) * 3.0 * 2.0) < 1e-12);
}

TEST_CASE("3-D walls: a dilute gas's wall pressure is Carnahan-Starling's at the density its centres reach") {
  // 500 spheres of diameter 1 at eta 0.02 in a closed box of side L. The force on a face is kT
  // times the contact density over the (L - 1)^2 its centres reach (the contact theorem), so
  // Z_w = p L^2 (L - 1) / (N kT), p the force per face area. Bulk: P = rho_b kT Z_CS(rho_b),
  // with rho_b below N / (L - 1)^3 by the walls' adsorption: to first order in rho a sphere near
  // a face misses a cap of its exclusion sphere, Gamma = rho^2 pi / 4 per area, so rho_b =
  // rho (1 - 9 eta / (L - 1)), 0.9 % here; edges and corners are O(1 / L^2). Z is then 1.085;
  // an ideal gas (no pressure from collisions) gives 1.000, forgetting the reach 0.92 or 1.19.
  sim::World3Def def = sim::fcc_gas3(5, 0.02, 7);
  def.boundary = sim::Boundary3::walls;
  sim::World3 w(def);
  const double n = static_cast<double>(w.sphere_count()), side = def.size.x;
  while (w.collisions() < 20 * n) w.advance_to(w.time() + 1.0);  // forget the lattice
  formats::ObserveOptions o;
  o.from = w.time();
  o.window = 150.0;
  const double until = o.from + 10 * o.window;
  formats::Observer obs(w, def, "dilute", o, until);
  obs.advance_to(until);
  const nlohmann::json out = obs.result();
  const double kT = 2.0 * w.kinetic_energy() / (3.0 * n);  // walls take momentum, not energy
  const double eta = n * kPi / 6.0 / std::pow(side - 1.0, 3.0);
  const double bulk = 1.0 - 9.0 * eta / (side - 1.0);
  const double expected = bulk * formats::carnahan_starling_z(bulk * eta);
  const double p = out["summary"]["pressure_walls"]["mean"], p_err = out["summary"]["pressure_walls"]["error"];
  const double to_z = side * side * (side - 1.0) / (n * kT);
  const double z = p * to_z, z_err = p_err * to_z;
  INFO("Z from the walls " << z << " +- " << z_err << ", expected " << expected);
  CHECK(z_err < 0.002);
  CHECK(std::abs(z - expected) < 3.0 * z_err + 0.006);
  // Each of the six faces, by itself, within its own error of the mean.
  REQUIRE(out["walls"].size() == 6);
  for (const auto& wall : out["walls"]) {
    INFO(wall.dump());
    CHECK(std::abs(double(wall["area"]) - (side * side)) < 1e-9 * side * side);
    CHECK(std::abs(double(wall["pressure"]["mean"]) - p) < 4.0 * double(wall["pressure"]["error"]) + 1e-12);
  }
  CHECK(out["walls"][0]["id"] == "wall-0");  // no ids given: wall-k
}
