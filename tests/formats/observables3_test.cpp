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
