// SPDX-License-Identifier: MIT
// The radial distribution function g(r) of the Observer (observables.hpp), per pair of species,
// and its contact values g(sigma+) (docs/physics.md, "Gas observables": for hard discs the virial
// gives Z = 1 + 2 eta g(sigma+), which the tests hold the contact value to).
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <utility>

#include "turtlegas/formats/observables.hpp"

namespace turtlegas::formats {
namespace {

constexpr double kPi = 3.14159265358979323846;

nlohmann::json block_of(const std::vector<double>& x) {
  const double n = static_cast<double>(x.size());
  const double m = x.empty() ? 0.0 : std::accumulate(x.begin(), x.end(), 0.0) / n;
  double ss = 0.0;
  for (double v : x) ss += (v - m) * (v - m);
  return {{"mean", m}, {"error", x.size() > 1 ? std::sqrt(ss / (n * (n - 1.0))) : 0.0}};
}

/// The contact value g(sigma+) of one window's g: a least-squares line through the centres of the
/// first bins wholly beyond sigma (at least 3, and as many as lie within 0.1 sigma of it), taken at
/// sigma. g falls off from contact with a slope of order g/sigma; over 0.1 sigma the curvature moves
/// a straight line's intercept by well under 1 % at the densities of a fluid.
double contact_value(const std::vector<double>& g, double width, double sigma) {
  const auto first = static_cast<std::size_t>(std::ceil(sigma / width - 1e-9));
  const std::size_t want = std::max<std::size_t>(3, static_cast<std::size_t>(std::ceil(0.1 * sigma / width)));
  double sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
  for (std::size_t b = first; b < g.size() && b < first + want; ++b) {
    const double x = (static_cast<double>(b) + 0.5) * width - sigma;
    sx += x, sy += g[b], sxx += x * x, sxy += x * g[b], n += 1.0;
  }
  if (n < 2.0) return n > 0.0 ? sy / n : 0.0;
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  return (sy - slope * sx) / n;
}

}  // namespace

std::size_t Observer::pair_index(std::size_t a, std::size_t b) const {
  if (a > b) std::swap(a, b);
  // Row-major upper triangle: pairs (0,0) (0,1) ... (0,S-1) (1,1) ...
  const std::size_t s = species_.size();
  return a * s - a * (a - 1) / 2 + (b - a);
}

double Observer::expected_pairs(std::size_t a, std::size_t b, double r0, double r1) const {
  if (dims_ == 3) {
    if (boundary_ == sim::Boundary::periodic) return 4.0 / 3.0 * kPi * (r1 * r1 * r1 - r0 * r0 * r0) / volume();
    // Two centres uniform in an a x b x c box are at distance r with density 4 pi r^2 K(r) / V^2,
    // K(r) = abc - r (ab + bc + ca)/2 + 2 r^2 (a + b + c)/(3 pi) - r^3/(4 pi) the box's set
    // covariance averaged over directions (r <= min(a, b, c)); F below is its integral over r. With
    // walls the centres keep their radii from the faces, as in 2-D.
    const double inset = boundary_ == sim::Boundary::walls ? species_[a].radius + species_[b].radius : 0.0;
    const double x = size_.x - inset, y = size_.y - inset, z = size_.z - inset;
    const double v = x * y * z, s2 = x * y + y * z + z * x, s1 = x + y + z;
    auto F = [&](double r) {
      const double r3 = r * r * r;
      return 4.0 * kPi * (v * r3 / 3.0 - s2 * r3 * r / 8.0 + 2.0 * s1 * r3 * r * r / (15.0 * kPi) - r3 * r3 / (24.0 * kPi));
    };
    return (F(r1) - F(r0)) / (v * v);
  }
  if (boundary_ == sim::Boundary::periodic) return kPi * (r1 * r1 - r0 * r0) / (width_ * height_);
  // Two centres uniform in an a x b rectangle are at distance r with density 2 pi r K(r) / (a b)^2,
  // K(r) = a b - 2 r (a + b)/pi + r^2/pi the rectangle's set covariance averaged over directions
  // (r <= min(a, b)); its integral F(r) = pi a b r^2 - 4/3 (a + b) r^3 + r^4/2. With walls the centres
  // of two discs of radii ra and rb keep ra and rb from the edges: the rectangle of their mean.
  const double inset = boundary_ == sim::Boundary::walls ? species_[a].radius + species_[b].radius : 0.0;
  const double w = width_ - inset, h = height_ - inset;
  auto F = [&](double r) { return kPi * w * h * r * r - 4.0 / 3.0 * (w + h) * r * r * r + 0.5 * r * r * r * r; };
  return (F(r1) - F(r0)) / (w * w * h * h);
}

void Observer::sample_pairs() {
  const bool periodic = boundary_ == sim::Boundary::periodic;
  const std::size_t S = species_.size();
  std::vector<std::size_t> alive_count(S, 0);
  struct Item {
    sim::Vec3 p;
    std::size_t species;
  };
  std::vector<Item> items;
  items.reserve(count());
  for (std::size_t i = 0; i < count(); ++i) {
    if (!alive(i)) continue;
    sim::Vec3 p = pos(i);
    if (periodic)
      for (int k = 0; k < dims_; ++k) p[k] -= size_[k] * std::floor(p[k] / size_[k]);
    items.push_back({p, species_of_[i]});
    ++alive_count[species_of_[i]];
  }
  for (std::size_t a = 0; a < S; ++a)
    for (std::size_t b = a; b < S; ++b) {
      const double na = static_cast<double>(alive_count[a]), nb = static_cast<double>(alive_count[b]);
      current_.pair_norm[pair_index(a, b)] += a == b ? na * (na - 1.0) / 2.0 : na * nb;
    }
  const std::size_t bins = static_cast<std::size_t>(opt_.rdf_bins);
  const double inv_width = static_cast<double>(bins) / rdf_max_, max2 = rdf_max_ * rdf_max_;
  auto count_pair = [&](const Item& p, const Item& q) {
    sim::Vec3 d = q.p - p.p;
    if (periodic)
      for (int k = 0; k < dims_; ++k) d[k] -= size_[k] * std::round(d[k] / size_[k]);
    const double r2 = dot(d, d);
    if (r2 >= max2) return;
    const auto bin = static_cast<std::size_t>(std::sqrt(r2) * inv_width);
    if (bin < bins) current_.pair_counts[pair_index(p.species, q.species) * bins + bin] += 1.0;
  };
  // Cells at least rdf_max wide: every pair within rdf_max lies in one cell or two neighbours.
  int n[3] = {1, 1, 1};
  for (int k = 0; k < dims_; ++k) n[k] = std::max(1, static_cast<int>(size_[k] / rdf_max_));
  if (periodic && (n[0] < 3 || n[1] < 3 || (dims_ == 3 && n[2] < 3))) {  // a neighbour met twice: all pairs
    for (std::size_t i = 0; i < items.size(); ++i)
      for (std::size_t j = i + 1; j < items.size(); ++j) count_pair(items[i], items[j]);
    return;
  }
  auto cell_of = [&](const sim::Vec3& p) {
    int c[3] = {0, 0, 0};
    for (int k = 0; k < dims_; ++k) c[k] = std::clamp(static_cast<int>(p[k] / size_[k] * n[k]), 0, n[k] - 1);
    return (c[2] * n[1] + c[1]) * n[0] + c[0];
  };
  const std::size_t cells = static_cast<std::size_t>(n[0] * n[1] * n[2]);
  std::vector<std::uint32_t> start(cells + 1, 0), order(items.size());
  for (const Item& it : items) ++start[static_cast<std::size_t>(cell_of(it.p)) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < items.size(); ++i) order[fill[static_cast<std::size_t>(cell_of(items[i].p))]++] = static_cast<std::uint32_t>(i);
  // Each cell with itself and half of its neighbours (those after it: dz > 0, or dz = 0 and dy > 0,
  // or dz = dy = 0 and dx > 0): every pair once. In 2-D only the plane's four.
  std::vector<std::array<int, 3>> half;
  for (int dz = 0; dz <= (dims_ == 3 ? 1 : 0); ++dz)
    for (int dy = dz > 0 ? -1 : 0; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (dz > 0 || dy > 0 || dx > 0) half.push_back({dx, dy, dz});
  for (int cz = 0; cz < n[2]; ++cz)
    for (int cy = 0; cy < n[1]; ++cy)
      for (int cx = 0; cx < n[0]; ++cx) {
        const std::size_t c = static_cast<std::size_t>((cz * n[1] + cy) * n[0] + cx);
        for (std::uint32_t i = start[c]; i < start[c + 1]; ++i)
          for (std::uint32_t j = i + 1; j < start[c + 1]; ++j) count_pair(items[order[i]], items[order[j]]);
        for (const auto& off : half) {
          int o[3] = {cx + off[0], cy + off[1], cz + off[2]};
          bool out = false;
          for (int k = 0; k < 3; ++k) {
            if (periodic) o[k] = (o[k] + n[k]) % n[k];
            else if (o[k] < 0 || o[k] >= n[k]) out = true;
          }
          if (out) continue;
          const std::size_t oc = static_cast<std::size_t>((o[2] * n[1] + o[1]) * n[0] + o[0]);
          for (std::uint32_t i = start[c]; i < start[c + 1]; ++i)
            for (std::uint32_t j = start[oc]; j < start[oc + 1]; ++j) count_pair(items[order[i]], items[order[j]]);
        }
      }
}

void Observer::pair_results(nlohmann::json& out, nlohmann::json& summary) const {
  const std::size_t bins = static_cast<std::size_t>(opt_.rdf_bins), S = species_.size();
  const double width = rdf_max_ / static_cast<double>(bins);
  nlohmann::json edges = nlohmann::json::array();
  for (std::size_t b = 0; b <= bins; ++b) edges.push_back(static_cast<double>(b) * width);
  // Per window: g of each pair of species and of all balls together; the windows' mean and block error.
  using Pair = std::pair<std::size_t, std::size_t>;
  auto table = [&](const std::vector<Pair>& pairs, double sigma, nlohmann::json& into) {
    std::vector<std::vector<double>> per_bin(bins);
    std::vector<double> contact;
    for (const Window& w : done_) {
      std::vector<double> g(bins, 0.0);
      for (std::size_t b = 0; b < bins; ++b) {
        double counts = 0.0, expected = 0.0;
        for (const auto& [a, c] : pairs) {
          const std::size_t p = pair_index(a, c);
          counts += w.pair_counts[p * bins + b];
          expected += w.pair_norm[p] * expected_pairs(a, c, static_cast<double>(b) * width, static_cast<double>(b + 1) * width);
        }
        g[b] = expected > 0.0 ? counts / expected : 0.0;
        per_bin[b].push_back(g[b]);
      }
      if (sigma > 0.0) contact.push_back(contact_value(g, width, sigma));
    }
    nlohmann::json g = nlohmann::json::array(), err = nlohmann::json::array();
    for (const auto& v : per_bin) {
      const nlohmann::json s = block_of(v);
      g.push_back(s["mean"]);
      err.push_back(s["error"]);
    }
    into["g"] = g;
    into["error"] = err;
    if (sigma > 0.0) into["contact"] = block_of(contact);
  };
  nlohmann::json rdf = {{"r_max", rdf_max_}, {"edges", edges}};
  std::vector<Pair> all;
  for (std::size_t a = 0; a < S; ++a)
    for (std::size_t b = a; b < S; ++b) all.emplace_back(a, b);
  table(all, S == 1 ? 2.0 * species_[0].radius : 0.0, rdf);
  if (S == 1) summary["g_contact"] = rdf["contact"];
  nlohmann::json pairs = nlohmann::json::array();
  if (S > 1)
    for (std::size_t a = 0; a < S; ++a)
      for (std::size_t b = a; b < S; ++b) {
        nlohmann::json p = {{"species", {a, b}}, {"sigma", species_[a].radius + species_[b].radius}};
        table({{a, b}}, species_[a].radius + species_[b].radius, p);
        pairs.push_back(p);
      }
  rdf["pairs"] = pairs;
  out["rdf"] = rdf;
}

}  // namespace turtlegas::formats
