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

namespace {

/// Runs `def` under an Observer with options `o` to `until`; the whole result.
nlohmann::json observed(const sim::WorldDef& def, const formats::ObserveOptions& o, double until) {
  World w(def, Mode::exact);
  formats::Observer obs(w, def, o, until);
  obs.advance_to(until);
  return obs.result();
}

}  // namespace

TEST_CASE("g(r): the contact value agrees with the virial's (Z - 1)/(2 eta), and g tends to 1", "[observables][physics]") {
  // Hard discs in two dimensions: P A = N kT + (1/2) <sum r . F> and, the force acting only at
  // contact, (1/2)<sum r . F>/(N kT) = (pi/2) n sigma^2 g(sigma+) = 2 eta g(sigma+) with
  // eta = n pi sigma^2/4 (docs/physics.md, "Gas observables"). So g(sigma+) = (Z - 1)/(2 eta), Z the
  // canonical one (the virial of a momentum-conserving run is 1/N low in its ideal part only).
  const double eta = 0.3;
  const int n = 1000;
  const std::uint64_t seed = 3531;
  INFO("seed " << seed);
  const sim::WorldDef def = random_gas(n, eta, 1.0, 1.0, seed, sim::Boundary::periodic);
  const double density = n / (def.arena.width * def.arena.height), sigma = 2.0;
  const double nu = 2.0 * density * sigma * formats::henderson_contact(eta) * std::sqrt(kPi * 0.5);
  formats::ObserveOptions o;
  o.from = 30.0 / nu;
  o.window = 20.0 / nu;
  o.samples = 100;  // a sample every 0.2 collisions per disc: the bins at contact fill
  const nlohmann::json j = observed(def, o, o.from + 10 * o.window);
  const auto& s = j.at("summary");
  const double z = mean_of(s.at("Z_canonical")), z_se = error_of(s.at("Z_canonical"));
  const double g_virial = (z - 1.0) / (2.0 * eta), g_virial_se = z_se / (2.0 * eta);
  const double g = mean_of(s.at("g_contact")), g_se = error_of(s.at("g_contact"));
  std::printf("eta 0.3: g(sigma+) %.4f +- %.4f, virial %.4f +- %.4f, Henderson %.4f\n", g, g_se, g_virial, g_virial_se,
              formats::henderson_contact(eta));
  INFO("g(sigma+) " << g << " +- " << g_se << ", virial " << g_virial << " +- " << g_virial_se);
  // Margin: 4 combined block errors and 1 % for the straight line through the first bins (their
  // curvature: Henderson's g falls by 0.6 % of itself per 0.01 sigma here, nearly linearly).
  CHECK(g_se < 0.01 * g);
  CHECK(std::abs(g - g_virial) <= 4.0 * std::hypot(g_se, g_virial_se) + 0.01 * g_virial);
  CHECK(std::abs(g - 1.0) > 0.5);  // the test can tell a gas of points from discs
  // Inside the core no pairs; far out g is 1 within its error and 1 % (the finite box's O(1/N)).
  const auto& rdf = j.at("rdf");
  const auto& edges = rdf.at("edges");
  double far = 0.0, far_n = 0.0;
  for (std::size_t b = 0; b < rdf.at("g").size(); ++b) {
    const double lo = edges[b].get<double>(), hi = edges[b + 1].get<double>(), gb = rdf.at("g")[b].get<double>();
    if (hi <= sigma) CHECK(gb == 0.0);
    if (lo >= 8.0) far += gb, far_n += 1.0;
  }
  REQUIRE(far_n > 10);
  CHECK(far / far_n == Approx(1.0).margin(0.01));
  CHECK(rdf.at("r_max").get<double>() == Approx(10.0));  // 5 diameters
}

TEST_CASE("g(r) behind walls: the rectangle's set covariance makes an ideal gas's g flat at 1", "[observables]") {
  // Points that pass through each other (ball_ball off) fill a walled box uniformly: g = 1 at every r
  // once the box's edges are allowed for. Without that (the periodic shell 2 pi r dr / A), g would
  // fall to 1 - 2r(a + b)/(pi a b) + ..., 0.7 at a quarter of the side.
  const std::uint64_t seed = 3532;
  INFO("seed " << seed);
  sim::WorldDef def = random_gas(400, 0.01, 0.5, 1.0, seed, sim::Boundary::walls);
  def.effects.ball_ball = false;
  formats::ObserveOptions o;
  o.from = 0.0;
  o.window = 400.0;
  o.samples = 40;
  o.rdf_max = def.arena.width / 2.0;
  o.rdf_bins = 25;
  const nlohmann::json j = observed(def, o, 10 * o.window);
  const auto& rdf = j.at("rdf");
  double chi2 = 0.0;
  std::size_t bins = 0;
  for (std::size_t b = 1; b < rdf.at("g").size(); ++b) {
    const double gb = rdf.at("g")[b].get<double>(), se = rdf.at("error")[b].get<double>();
    INFO("bin " << b << ": g " << gb << " +- " << se);
    CHECK(std::abs(gb - 1.0) < 0.03);
    chi2 += (gb - 1.0) * (gb - 1.0) / (se * se);
    ++bins;
  }
  INFO("chi^2 per bin " << chi2 / bins);
  CHECK(chi2 / bins < 3.0);
}

TEST_CASE("MSD in a periodic box: unwrapped coordinates follow free flight across many box lengths", "[observables]") {
  // Without collisions every ball flies straight: MSD(tau) = <|v - V|^2> tau^2 exactly, though each
  // ball crosses the box several times per window. A wrapped coordinate could not grow beyond the box.
  const std::uint64_t seed = 3533;
  INFO("seed " << seed);
  sim::WorldDef def = random_gas(200, 0.01, 1.0, 1.0, seed, sim::Boundary::periodic);
  def.effects.ball_ball = false;
  formats::ObserveOptions o;
  o.window = 5.0 * def.arena.width;  // five crossings at speed 1
  o.samples = 10;
  const nlohmann::json j = observed(def, o, 2 * o.window);
  const auto& m = j.at("msd");
  const double v2 = j.at("vacf").at("vacf")[0].get<double>();
  CHECK(v2 == Approx(1.0).epsilon(0.02));  // speed 1, less the centre of mass's small drift
  for (std::size_t k = 0; k < m.at("lag").size(); ++k) {
    const double tau = m.at("lag")[k].get<double>();
    CHECK(m.at("msd")[k].get<double>() == Approx(v2 * tau * tau).epsilon(1e-9).margin(1e-9));
  }
  CHECK(m.at("msd").back().get<double>() > 10.0 * def.arena.width * def.arena.width);
}

TEST_CASE("self-diffusion of hard discs: Enskog's D at two densities, and Green-Kubo's integral of the VACF "
          "equals the MSD's slope", "[observables][physics]") {
  // Enskog's D for hard discs (first Sonine approximation; Gass, J. Chem. Phys. 54, 1898 (1971)):
  // D_E = 1/(2 n sigma g(sigma)) sqrt(kT/(pi m)), the tagged disc's velocity relaxing at the
  // collision rate 2 n sigma g sqrt(pi kT/m) (in two dimensions the two rates are equal). Chapman's
  // dilute value is the same without g(sigma): Enskog's finite-density correction, 1.08 at eta = 0.05
  // and 1.43 at 0.2 (Henderson's contact value).
  // Tolerance, plus 4 block errors: D/D_E within [0.98, 1.12] at eta = 0.05 and [1.05, 1.40] at 0.2.
  // The second Sonine approximation raises D by about 2 %; correlated collisions (ring collisions,
  // the 2-D long-time tail t^-1 of the VACF, whose integral grows as the log of the time) raise it
  // further with density: molecular dynamics of discs (Alder, Gass and Wainwright, J. Chem. Phys. 53,
  // 3813 (1970); Erpenbeck and Wood, Phys. Rev. A 43, 4254 (1991)) finds D/D_E a few per cent above
  // 1 in the dilute gas and 1.2-1.3 near eta = 0.2 over tens of collision times (this run: 1.07 and
  // 1.23). Chapman's dilute value, 1.43 D_E at eta = 0.2, falls outside: the correction is seen.
  const std::vector<std::pair<double, std::pair<double, double>>> cases{{0.05, {0.98, 1.12}}, {0.2, {1.05, 1.40}}};
  for (const auto& [eta, band] : cases) {
    const int n = 1000;
    const std::uint64_t seed = 3534 + static_cast<std::uint64_t>(eta * 100);
    INFO("eta " << eta << ", seed " << seed);
    const sim::WorldDef def = random_gas(n, eta, 1.0, 1.0, seed, sim::Boundary::periodic);
    const double density = n / (def.arena.width * def.arena.height), sigma = 2.0, g = formats::henderson_contact(eta);
    const double nu = 2.0 * density * sigma * g * std::sqrt(kPi * 0.5);
    formats::ObserveOptions o;
    o.from = 20.0 / nu;
    o.window = 30.0 / nu;  // thirty collision times: the MSD's slope from 15 on
    o.samples = 150;       // five samples per collision time, for the VACF's integral
    const nlohmann::json j = observed(def, o, o.from + 16 * o.window);
    const auto& s = j.at("summary");
    const double kT = mean_of(s.at("kT"));
    const double d_enskog = 1.0 / (2.0 * density * sigma * g) * std::sqrt(kT / kPi);
    const double d = mean_of(s.at("D_msd")), d_se = error_of(s.at("D_msd"));
    const double d_gk = mean_of(s.at("D_green_kubo")), d_gk_se = error_of(s.at("D_green_kubo"));
    std::printf("eta %.2f: D_msd %.4f +- %.4f, D_green_kubo %.4f +- %.4f, Enskog %.4f (ratio %.3f)\n", eta, d, d_se,
                d_gk, d_gk_se, d_enskog, d / d_enskog);
    INFO("D_msd " << d << " +- " << d_se << ", Green-Kubo " << d_gk << " +- " << d_gk_se << ", Enskog " << d_enskog);
    CHECK(d_se < 0.02 * d);
    CHECK(d >= band.first * d_enskog - 4.0 * d_se);
    CHECK(d <= band.second * d_enskog + 4.0 * d_se);
    if (eta >= 0.2) CHECK(d_enskog * g - d > 4.0 * d_se + 0.05 * d);  // Chapman's D is far above
    // Green-Kubo against Einstein on the same samples: MSD(tau) = 2 int_0^tau (tau - s) C(s) ds, lag
    // by lag, by the trapezoidal rule on the sample grid (its error at 5 samples per collision time:
    // under 1 %, C decaying at about the collision rate); and the two D's.
    const auto& lag = j.at("msd").at("lag");
    const auto& msd = j.at("msd").at("msd");
    const auto& c = j.at("vacf").at("vacf");
    CHECK(c[0].get<double>() == Approx(2.0 * kT).epsilon(0.01));  // <v^2> = 2 kT/m
    const double h = lag[1].get<double>();
    for (std::size_t k = 10; k < lag.size(); k += 20) {
      double integral = 0.0;
      for (std::size_t i = 0; i < k; ++i)
        integral += 0.5 * h * ((lag[k].get<double>() - lag[i].get<double>()) * c[i].get<double>() +
                               (lag[k].get<double>() - lag[i + 1].get<double>()) * c[i + 1].get<double>());
      const double se = j.at("msd").at("error")[k].get<double>();
      INFO("lag " << lag[k].get<double>() << ": MSD " << msd[k].get<double>() << " +- " << se << ", from the VACF "
                  << 2.0 * integral);
      CHECK(std::abs(msd[k].get<double>() - 2.0 * integral) <= 4.0 * se + 0.01 * msd[k].get<double>());
    }
    CHECK(std::abs(d_gk - d) <= 4.0 * std::hypot(d_se, d_gk_se) + 0.01 * d);
  }
}

TEST_CASE("a binary mixture: one temperature, the virial from the partial contact values, the heavy discs slower",
          "[observables][physics]") {
  // 500 discs of radius 1 and mass 1 with 500 of radius 1.5 and mass 4, periodic. The virial of a
  // mixture of hard discs: Z - 1 = (pi/2) sum_a sum_b x_a x_b n sigma_ab^2 g_ab(sigma_ab+), x the
  // species' fractions and sigma_ab = r_a + r_b; the partial g's contact values must give the
  // pressure measured from the collisions' impulses.
  const std::uint64_t seed = 3535;
  INFO("seed " << seed);
  sim::WorldDef def = random_gas(1000, 0.35, 1.5, 1.0, seed, sim::Boundary::periodic);
  for (std::size_t i = 0; i < def.balls.size(); i += 2) def.balls[i].radius = 1.0;
  for (std::size_t i = 1; i < def.balls.size(); i += 2) def.balls[i].mass = 4.0;
  const double area = def.arena.width * def.arena.height, n = 1000.0 / area;
  formats::ObserveOptions o;
  o.from = 100.0;
  o.window = 60.0;
  o.samples = 60;
  const nlohmann::json j = observed(def, o, o.from + 10 * o.window);
  const auto& sp = j.at("species");
  REQUIRE(sp.size() == 2);
  CHECK(sp[0].at("radius").get<double>() == 1.0);
  CHECK(sp[1].at("mass").get<double>() == 4.0);
  CHECK(sp[0].at("count").get<int>() == 500);
  const double t0 = mean_of(sp[0].at("kT")), t1 = mean_of(sp[1].at("kT"));
  const double t_se = std::hypot(error_of(sp[0].at("kT")), error_of(sp[1].at("kT")));
  INFO("kT " << t0 << " and " << t1 << " +- " << t_se);
  CHECK(std::abs(t0 - t1) <= 4.0 * t_se + 0.005 * t0);  // equipartition (0.5 %: each species' 2N dof)
  const auto& pairs = j.at("rdf").at("pairs");
  REQUIRE(pairs.size() == 3);
  double sum = 0.0, sum_se2 = 0.0;
  for (const auto& p : pairs) {
    const double sigma = p.at("sigma").get<double>(), g = mean_of(p.at("contact")), se = error_of(p.at("contact"));
    const bool same = p.at("species")[0] == p.at("species")[1];
    const double w = (kPi / 2.0) * n * 0.25 * sigma * sigma * (same ? 1.0 : 2.0);
    std::printf("mixture: g_%d%d(%.1f+) = %.4f +- %.4f\n", p.at("species")[0].get<int>(), p.at("species")[1].get<int>(),
                sigma, g, se);
    sum += w * g;
    sum_se2 += w * w * se * se;
  }
  const double z = mean_of(j.at("summary").at("Z_canonical")), z_se = error_of(j.at("summary").at("Z_canonical"));
  std::printf("mixture: Z - 1 = %.4f +- %.4f, from the contact values %.4f +- %.4f\n", z - 1.0, z_se, sum,
              std::sqrt(sum_se2));
  INFO("Z - 1 " << z - 1.0 << " +- " << z_se << ", from the contacts " << sum);
  CHECK(std::abs((z - 1.0) - sum) <= 4.0 * std::hypot(z_se, std::sqrt(sum_se2)) + 0.01 * (z - 1.0));
  // The heavier, larger discs diffuse more slowly.
  CHECK(mean_of(sp[1].at("D_msd")) < 0.7 * mean_of(sp[0].at("D_msd")));
}

TEST_CASE("MSD and VACF behind walls equal a direct computation from the same samples", "[observables]") {
  // Walls do not wrap coordinates: the observer's MSD and VACF at every lag must be what the states at
  // the sample times give, computed here by hand (lab frame, every sample of a window an origin).
  const std::uint64_t seed = 3536;
  INFO("seed " << seed);
  const sim::WorldDef def = random_gas(300, 0.2, 1.0, 1.0, seed, sim::Boundary::walls);
  formats::ObserveOptions o;
  o.from = 2.0;
  o.window = 3.0;
  o.samples = 6;
  const nlohmann::json j = observed(def, o, o.from + 2 * o.window);
  World w(def, Mode::exact);
  std::vector<std::vector<sim::BallState>> frames;  // 0..12
  for (int k = 0; k <= 2 * o.samples; ++k) {
    w.advance_to(o.from + k * o.window / o.samples);
    std::vector<sim::BallState> f;
    for (std::size_t i = 0; i < w.ball_count(); ++i) f.push_back(w.ball(i));
    frames.push_back(f);
  }
  for (int lag = 0; lag <= o.samples; ++lag) {
    double msd = 0.0, vacf = 0.0;
    for (int win = 0; win < 2; ++win) {
      double m = 0.0, c = 0.0, n = 0.0;
      for (int i = 0; i + lag <= o.samples; ++i) {
        const auto &a = frames[static_cast<std::size_t>(win * o.samples + i)], &b = frames[static_cast<std::size_t>(win * o.samples + i + lag)];
        for (std::size_t k = 0; k < a.size(); ++k) m += norm2(b[k].pos - a[k].pos), c += dot(a[k].vel, b[k].vel), n += 1.0;
      }
      msd += m / n / 2.0, vacf += c / n / 2.0;
    }
    const auto l = static_cast<std::size_t>(lag);
    INFO("lag " << lag);
    CHECK(j.at("msd").at("msd")[l].get<double>() == Approx(msd).epsilon(1e-9).margin(1e-12));
    CHECK(j.at("vacf").at("vacf")[l].get<double>() == Approx(vacf).epsilon(1e-9));
  }
  CHECK(j.at("msd").at("msd")[static_cast<std::size_t>(o.samples)].get<double>() > 0.5);  // they moved
}
