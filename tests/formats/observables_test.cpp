// SPDX-License-Identifier: MIT
// The gas observables (formats/observables.hpp) against the theory of hard discs: relaxation to the
// 2-D Maxwell-Boltzmann (Rayleigh) speed distribution, Henderson's equation of state and Enskog's
// collision rate, the barometric profile and the floor's load under gravity. Every scene is seeded;
// the tolerances are stated beside each check (block standard errors "se" from the observer's
// windows, and the equation of state's own error where it enters).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

#include <catch2/catch.hpp>

#include "../sim/scenes.hpp"
#include "turtlegas/formats/observables.hpp"

using namespace turtlegas;
using sim::Mode;
using sim::World;
using test::random_gas;

namespace {

constexpr double kPi = 3.14159265358979323846;

double rayleigh_cdf(double v, double kT) { return 1.0 - std::exp(-v * v / (2.0 * kT)); }
/// The 3-D Maxwell speed distribution with the same mean square speed (2 kT in 2-D): the wrong
/// distribution a 2-D gas must be told apart from.
double maxwell3_cdf(double v, double mean_sq) {
  const double a = std::sqrt(mean_sq / 3.0);
  return std::erf(v / (a * std::sqrt(2.0))) - std::sqrt(2.0 / kPi) * v / a * std::exp(-v * v / (2.0 * a * a));
}

/// Kolmogorov-Smirnov distance of a sample from a distribution function.
template <class Cdf>
double ks_distance(std::vector<double> x, Cdf cdf) {
  std::sort(x.begin(), x.end());
  const double n = static_cast<double>(x.size());
  double d = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double f = cdf(x[i]);
    d = std::max({d, std::abs(f - static_cast<double>(i) / n), std::abs(static_cast<double>(i + 1) / n - f)});
  }
  return d;
}

/// Speeds about the centre of mass and kT over 2(N - 1) degrees of freedom (a periodic gas).
std::vector<double> speeds(const World& w, double& kT) {
  sim::Vec2 p{};
  double m = 0.0;
  for (std::size_t i = 0; i < w.ball_count(); ++i) p += w.mass(i) * w.ball(i).vel, m += w.mass(i);
  std::vector<double> s;
  double twice_ke = 0.0;
  for (std::size_t i = 0; i < w.ball_count(); ++i) {
    const sim::Vec2 u = w.ball(i).vel - p / m;
    s.push_back(norm(u));
    twice_ke += w.mass(i) * dot(u, u);
  }
  kT = twice_ke / (2.0 * (static_cast<double>(s.size()) - 1.0));
  return s;
}

double mean_of(const nlohmann::json& j) { return j.at("mean").get<double>(); }

/// Runs w under an Observer from `from` in `windows` whole windows of `window` seconds, 4 samples
/// each; the result's summary.
nlohmann::json observed_summary(World& w, const sim::WorldDef& def, double from, double window, int windows) {
  formats::ObserveOptions o;
  o.from = from;
  o.window = window;
  o.samples = 4;
  const double until = from + windows * window;
  formats::Observer obs(w, def, o, until);
  obs.advance_to(until);
  REQUIRE(obs.windows() == static_cast<std::size_t>(windows));
  return obs.result().at("summary");
}
double error_of(const nlohmann::json& j) { return j.at("error").get<double>(); }

}  // namespace

TEST_CASE("a gas started at one speed relaxes to the Rayleigh distribution, and a wrong one fails the test",
          "[observables][physics]") {
  // 2000 discs, area fraction 0.1, periodic, every speed 1 in a random direction (seed 14).
  const std::uint64_t seed = 14;
  INFO("seed " << seed);
  World w(random_gas(2000, 0.1, 1.0, 1.0, seed, sim::Boundary::periodic), Mode::exact);
  double kT0 = 0.0;
  const std::vector<double> start = speeds(w, kT0);
  // Kolmogorov-Smirnov at significance 1e-3: D > 1.949 / sqrt(N) rejects. The speeds of one snapshot
  // are independent up to O(1/N) (the fixed total energy), which the 0.1 % level does not see.
  const double critical = 1.949 / std::sqrt(2000.0);
  // The start (a delta at the rms speed) fails it, by far.
  CHECK(ks_distance(start, [&](double v) { return rayleigh_cdf(v, kT0); }) > critical);
  formats::ObserveOptions o;
  o.from = 100.0;  // about 19 collisions per ball (Enskog: 0.19 per second)
  o.window = 30.0;
  o.samples = 6;   // 5 s apart, about one collision per ball: a new sample each time
  formats::Observer obs(w, random_gas(2000, 0.1, 1.0, 1.0, seed, sim::Boundary::periodic), o, 400.0);
  obs.advance_to(400.0);
  REQUIRE(obs.windows() == 10);
  double kT = 0.0;
  const std::vector<double> end = speeds(w, kT);
  CHECK(kT == Approx(kT0).epsilon(1e-12));  // energy is conserved exactly
  const double d_rayleigh = ks_distance(end, [&](double v) { return rayleigh_cdf(v, kT); });
  const double d_maxwell3 = ks_distance(end, [&](double v) { return maxwell3_cdf(v, 2.0 * kT); });
  INFO("KS distance from Rayleigh " << d_rayleigh << ", from the 3-D Maxwell " << d_maxwell3 << ", critical "
                                    << critical);
  CHECK(d_rayleigh < critical);
  CHECK(d_maxwell3 > critical);  // the test tells the two apart
  // The observer's histogram: every bin within its block error bars of the Rayleigh curve
  // (chi^2 per bin, block errors from 10 windows: expected about 1.3; the bound 3 is a >5-sigma
  // excursion of the mean of 40 such terms), while the 3-D Maxwell curve is far outside.
  const nlohmann::json j = obs.result();
  const auto& h = j.at("speed_histogram");
  double chi2 = 0.0, chi2_wrong = 0.0;
  int bins = 0;
  const double T = mean_of(j.at("summary").at("kT"));
  for (std::size_t b = 0; b < h.at("density").size(); ++b) {
    const double se = h.at("error")[b].get<double>();
    if (se <= 0.0) continue;  // the empty far tail
    const double lo = h.at("edges")[b].get<double>(), hi = h.at("edges")[b + 1].get<double>();
    const double f = h.at("density")[b].get<double>(), r = h.at("rayleigh")[b].get<double>();
    CHECK(r == Approx((rayleigh_cdf(hi, T) - rayleigh_cdf(lo, T)) / (hi - lo)).margin(1e-12));
    const double wrong = (maxwell3_cdf(hi, 2 * T) - maxwell3_cdf(lo, 2 * T)) / (hi - lo);
    chi2 += (f - r) * (f - r) / (se * se);
    chi2_wrong += (f - wrong) * (f - wrong) / (se * se);
    ++bins;
  }
  INFO("chi^2 per bin: Rayleigh " << chi2 / bins << ", 3-D Maxwell " << chi2_wrong / bins << " over " << bins);
  CHECK(bins >= 25);
  CHECK(chi2 / bins < 3.0);
  CHECK(chi2_wrong / bins > 30.0);
}

TEST_CASE("hard discs: Z = PA/(NkT) from the virial and the collision rate agree with Henderson and Enskog",
          "[observables][physics]") {
  // Henderson's Z = (1 + eta^2/8)/(1 - eta)^2 is a fit, not exact: the margin allowed for it is
  // 0.1 % of Z at eta = 0.1 (the virial series to B6 gives 1.23614 there, Henderson 1.23611),
  // 0.5 % at 0.3 and 1.2 % at 0.5 (1000 discs measure 4.09-4.12 there over several seeds and
  // sizes, Henderson says 4.125), on top of 4 block standard errors. The Enskog rate
  // 2 n sigma g(sigma) sqrt(pi kT/m) is exact given the true contact value g = (Z - 1)/(2 eta), so
  // its margin is the same model error carried over to g: margin(Z) Z/(Z - 1), relative.
  const std::vector<std::pair<double, double>> cases{{0.1, 0.001}, {0.3, 0.005}, {0.5, 0.012}};
  for (const auto& [eta, margin] : cases) {
    const std::uint64_t seed = 1400 + static_cast<std::uint64_t>(eta * 10);
    INFO("eta " << eta << ", seed " << seed);
    const int n = 1000;
    const sim::WorldDef def = random_gas(n, eta, 1.0, 1.0, seed, sim::Boundary::periodic);
    World w(def, Mode::exact);
    const double area = def.arena.width * def.arena.height, density = n / area, sigma = 2.0;
    const double kT = 0.5 * (1.0 - 1.0 / n);  // speed 1 each, less the centre of mass's share (about)
    const double nu_h = 2.0 * density * sigma * formats::henderson_contact(eta) * std::sqrt(kPi * kT);
    // From 30 collisions per ball, 10 windows of 20 per ball.
    const nlohmann::json s = observed_summary(w, def, 30.0 / nu_h, 20.0 / nu_h, 10);
    const double z = mean_of(s.at("Z_virial")), z_se = error_of(s.at("Z_virial"));
    const double zh = formats::henderson_z(eta);
    const double T = mean_of(s.at("kT"));
    const double nu = mean_of(s.at("collision_rate")), nu_se = error_of(s.at("collision_rate"));
    const double nu_e = 2.0 * density * sigma * formats::henderson_contact(eta) * std::sqrt(kPi * T);
    std::printf("eta %.1f: Z %.5f +- %.5f (Henderson %.5f), rate %.5f +- %.5f (Enskog %.5f), kT %.6f\n", eta, z, z_se,
                zh, nu, nu_se, nu_e, T);
    INFO("Z " << z << " +- " << z_se << " Henderson " << zh << "; rate " << nu << " +- " << nu_se << " Enskog " << nu_e);
    CHECK(z_se < 0.003 * z);  // error bars small enough for the test to mean something
    const double rate_margin = margin * zh / (zh - 1.0);
    CHECK(std::abs(z - zh) <= 4.0 * z_se + margin * zh);
    CHECK(nu_se < 0.005 * nu);
    CHECK(std::abs(nu - nu_e) <= 4.0 * nu_se + rate_margin * nu_e);
    // The same data cannot pass for an ideal gas, nor for the rate without the contact value
    // (g = 1): the checks above can fail.
    CHECK(std::abs(z - 1.0) > 4.0 * z_se + margin * zh);
    CHECK(std::abs(nu - nu_e / formats::henderson_contact(eta)) > 4.0 * nu_se + rate_margin * nu_e);
    // Mean free path: <|v|> / nu, Enskog's 1/(2 sqrt(2) n sigma g), with the rate's margins and
    // 0.2 % for <|v|> (40 samples of 1000 speeds: its standard error is about 0.1 %).
    const double mfp = mean_of(s.at("mean_free_path"));
    CHECK(mfp == Approx(1.0 / (2.0 * std::sqrt(2.0) * density * sigma * formats::henderson_contact(eta)))
                     .epsilon(rate_margin + 4.0 * nu_se / nu + 0.002));
  }
}

namespace {

/// n discs of radius 1 at area fraction eta in a square periodic box, on the staggered (centred
/// rectangular) lattice rows x cols = n (rows even, so it tiles the box) with the widest
/// nearest-neighbour gap, speeds 1 in seeded random directions: dense enough for eta = 0.72 at
/// n = 72, where the square lattice of random_gas overlaps.
sim::WorldDef staggered_square_gas(int n, double eta, std::uint64_t seed) {
  const double side = std::sqrt(n * kPi / eta);
  sim::WorldDef d = test::box(side, side, sim::Boundary::periodic);
  int best_rows = 0;
  double best_gap = 0.0;
  for (int rows = 2; rows <= n; rows += 2) {
    if (n % rows != 0) continue;
    const double px = side / (n / rows), py = side / rows;
    const double gap = std::min({px, std::hypot(px / 2, py), 2 * py});
    if (gap > best_gap) best_gap = gap, best_rows = rows;
  }
  REQUIRE(best_gap > 2.0);
  const int cols = n / best_rows;
  const double px = side / cols, py = side / best_rows;
  std::mt19937_64 rng(seed);
  auto uniform = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  for (int i = 0; i < n; ++i) {
    const int row = i / cols, col = i % cols;
    const sim::Vec2 centre{(col + 0.25 + 0.5 * (row % 2)) * px, (row + 0.5) * py};
    const double a = 2 * kPi * uniform();
    d.balls.push_back(test::ball("g" + std::to_string(i), centre, {std::cos(a), std::sin(a)}, 1.0));
  }
  return d;
}

}  // namespace

TEST_CASE("near the liquid-hexatic transition: 72 discs in a square box against Li et al. (2022)'s ECMC pressure, "
          "canonical ensemble exactly 1/N above ours",
          "[observables][physics]") {
  // Li, Nishikawa, Hoellmer, Maggs, Krauth, J. Chem. Phys. 157, 234111 (2022), "Hard-disk computer
  // simulations - a historic perspective", data in jellyfysh/HistoricDisks (DigitizedData/ThisWork.csv):
  // N = 72, aspect ratio 1:1, periodic, event-chain Monte Carlo (canonical), beta P (2 sigma)^2 with
  // sigma the radius, at packing fraction 0.65: 6.901074 +- 0.000071. In Z = beta P A / N that is
  // 6.901074 pi / (4 eta). A momentum-conserving run measures Z_virial = Z_canonical - 1/N
  // (docs/physics.md, "Gas observables", "Which ensemble"): at N = 72 the difference, 0.0139, is
  // ~9 of this run's standard errors, so the check below tells the ensembles apart.
  const int n = 72;
  const double eta = 0.65, ref = 6.901074 * kPi / (4.0 * eta), ref_se = 0.000071 * kPi / (4.0 * eta);
  const std::uint64_t seed = 7265;
  INFO("seed " << seed);
  const sim::WorldDef def = staggered_square_gas(n, eta, seed);
  World w(def, Mode::exact);
  // From ~1,300 collisions per disc after the lattice (melted and relaxed), 16 windows of ~15,000
  // per disc, far beyond the correlation time.
  const nlohmann::json s = observed_summary(w, def, 200.0, 2500.0, 16);
  const double zc = mean_of(s.at("Z_canonical")), se = std::hypot(error_of(s.at("Z_canonical")), ref_se);
  const double zv = mean_of(s.at("Z_virial"));
  std::printf("N 72, eta 0.65: Z_canonical %.5f +- %.5f, Z_virial %.5f, Li et al. %.5f\n", zc, se, zv, ref);
  INFO("Z_canonical " << zc << " +- " << se << ", Z_virial " << zv << ", reference " << ref);
  CHECK(zc - zv == Approx(1.0 / n).epsilon(1e-9));
  CHECK(se < 0.25 / n);                      // precise enough to see the ensembles' 1/N
  CHECK(std::abs(zc - ref) <= 4.0 * se);     // the canonical pressure agrees with Monte Carlo
  CHECK(std::abs(zv - ref) > 4.0 * se);      // and ours, taken for it, would not
  CHECK(std::abs(zc - formats::henderson_z(eta)) > 4.0 * se);  // nor would Henderson's fit (8.27)
}

namespace {

/// Density of hard discs in a column under gravity in the local-density approximation:
/// dp/dy = -n m g with p = n kT Z(eta), eta = n pi r^2, Henderson's Z: dn/dy = -n m g / (kT d(nZ)/dn).
/// Centres fill [r, H - r]; returns the density at the heights `ys` for a column holding `per_width`
/// centres per unit of accessible width.
std::vector<double> column_density(double per_width, double mg_over_kT, double r, double H, const std::vector<double>& ys,
                                   bool with_eos) {
  const double a = kPi * r * r;
  auto slope = [&](double n) {
    const double eta = n * a;
    if (!with_eos) return -n * mg_over_kT;
    const double dz = (eta / 4.0 * (1.0 - eta) + 2.0 * (1.0 + eta * eta / 8.0)) / std::pow(1.0 - eta, 3);  // Z'
    return -n * mg_over_kT / (formats::henderson_z(eta) + eta * dz);
  };
  const int steps = 20000;
  const double h = (H - 2 * r) / steps;
  auto integrate = [&](double n0, std::vector<double>* out) {
    double n = n0, total = 0.0, y = r;
    std::size_t k = 0;
    for (int s = 0; s < steps; ++s) {
      while (out && k < ys.size() && ys[k] <= y + h) out->push_back(n), ++k;  // (steps fine: 0.02 units)
      const double k1 = slope(n), k2 = slope(n + h / 2 * k1), k3 = slope(n + h / 2 * k2), k4 = slope(n + h * k3);
      const double next = n + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      total += h / 2 * (n + next);
      n = next;
      y += h;
    }
    while (out && k < ys.size()) out->push_back(n), ++k;
    return total;
  };
  double lo = 0.0, hi = 1.0 / a;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (integrate(mid, nullptr) < per_width ? lo : hi) = mid;
  }
  std::vector<double> out;
  integrate(0.5 * (lo + hi), &out);
  return out;
}

}  // namespace

TEST_CASE("under gravity the density falls off barometrically and the floor carries the gas's weight",
          "[observables][physics]") {
  // 1000 discs (r = 1, m = 1, speed 1) in a 400 x 400 box, g = 2.5e-3 down: m g H / kT about 2.
  const std::uint64_t seed = 1414;
  INFO("seed " << seed);
  sim::WorldDef def = random_gas(1000, 0.0196, 1.0, 1.0, seed, sim::Boundary::walls);
  def.effects.gravity = {0.0, -2.5e-3};
  const double H = def.arena.height, width = def.arena.width, r = 1.0, g = 2.5e-3;
  World w(def, Mode::exact);
  formats::ObserveOptions o;
  o.from = 4000.0;  // ten crossings of the box at the speed of sound, ~100 collisions per ball
  o.window = 1000.0;
  o.samples = 20;
  o.profile_bins = 20;
  const double until = o.from + 12 * o.window;
  formats::Observer obs(w, def, o, until);
  obs.advance_to(until);
  const nlohmann::json j = obs.result();
  const double kT = mean_of(j.at("summary").at("kT"));
  // The floor's load: what the floor takes minus what the ceiling takes is the weight N m g, on
  // average exactly (the side walls push sideways). Margin: 4 block errors.
  double floor = 0, floor_se = 0, ceiling = 0, ceiling_se = 0;
  for (std::size_t k = 0; k < w.walls().size(); ++k) {
    const sim::WallDef& wall = w.walls()[k];
    const auto& p = j.at("walls")[k].at("pressure");
    if (wall.from.y == 0.0 && wall.to.y == 0.0) floor = mean_of(p), floor_se = error_of(p);
    if (wall.from.y == H && wall.to.y == H) ceiling = mean_of(p), ceiling_se = error_of(p);
  }
  const double load = (floor - ceiling) * width, weight = 1000.0 * 1.0 * g;
  const double load_se = std::hypot(floor_se, ceiling_se) * width;
  INFO("floor load " << load << " +- " << load_se << ", weight " << weight << ", kT " << kT);
  CHECK(load_se < 0.02 * weight);
  CHECK(std::abs(load - weight) <= 4.0 * load_se);
  // The profile, bin by bin, against the column's density (Henderson's EOS in the local-density
  // approximation), averaged over each bin. The bins at the floor and the ceiling are left out:
  // within a diameter of a hard wall the density is raised by the wall's contact value (about 2 eta
  // g(sigma), 5 % here), which the local approximation does not know. Margin: 4 block errors and
  // 1 % for the EOS and the temperature's error.
  const auto& prof = j.at("density_profile");
  const std::size_t bins = prof.at("density").size();
  const double pw = H / static_cast<double>(bins);
  std::vector<double> ys;
  for (double y = 0.0; y <= H; y += 0.05) ys.push_back(y);
  auto expected = [&](const std::vector<double>& n, std::size_t b) {
    double sum = 0.0;
    int c = 0;
    for (std::size_t k = 0; k < ys.size(); ++k)
      if (ys[k] >= b * pw && ys[k] < (b + 1) * pw) sum += (ys[k] >= r && ys[k] <= H - r) ? n[k] : 0.0, ++c;
    return sum / c * (width - 2 * r) / width;  // the observer divides by the full width
  };
  const double per_width = 1000.0 / (width - 2 * r);
  const std::vector<double> n_eos = column_density(per_width, g / kT, r, H, ys, true);
  const std::vector<double> n_ideal = column_density(per_width, g / kT, r, H, ys, false);
  const std::vector<double> n_hot = column_density(per_width, g / (1.2 * kT), r, H, ys, true);
  int misses = 0, misses_hot = 0;
  for (std::size_t b = 1; b + 1 < bins; ++b) {
    const double meas = prof.at("density")[b].get<double>(), se = prof.at("error")[b].get<double>();
    const double theory = expected(n_eos, b), ideal = expected(n_ideal, b), hot = expected(n_hot, b);
    INFO("bin " << b << ": " << meas << " +- " << se << ", theory " << theory << ", ideal gas " << ideal);
    CHECK(std::abs(meas - theory) <= 4.0 * se + 0.01 * theory);
    misses += std::abs(meas - theory) > 4.0 * se + 0.01 * theory ? 1 : 0;
    misses_hot += std::abs(meas - hot) > 4.0 * se + 0.01 * hot ? 1 : 0;
  }
  CHECK(misses == 0);
  // A temperature 20 % off (a profile 20 % less steep) fails in most bins: the test can fail.
  CHECK(misses_hot >= 6);
  // The density at the floor is about 2.3 times the mean, at the ceiling a third of it.
  CHECK(prof.at("density")[1].get<double>() > 3.0 * prof.at("density")[bins - 2].get<double>());
}
