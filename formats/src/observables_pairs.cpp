// SPDX-License-Identifier: MIT
// The radial distribution function g(r) of the Observer (observables.hpp), per pair of species,
// and its contact values g(sigma+) (docs/physics.md, "Gas observables": for hard discs the virial
// gives Z = 1 + 2 eta g(sigma+), which the tests hold the contact value to).
#include <algorithm>
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
  const sim::World& w = *world_;
  const bool periodic = boundary_ == sim::Boundary::periodic;
  const std::size_t S = species_.size();
  std::vector<std::size_t> alive_count(S, 0);
  struct Item {
    sim::Vec2 p;
    std::size_t species;
  };
  std::vector<Item> items;
  items.reserve(w.ball_count());
  for (std::size_t i = 0; i < w.ball_count(); ++i) {
    const sim::BallState b = w.ball(i);
    if (!b.alive) continue;
    sim::Vec2 p = b.pos;
    if (periodic) p.x -= width_ * std::floor(p.x / width_), p.y -= height_ * std::floor(p.y / height_);
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
  auto count = [&](const Item& p, const Item& q) {
    sim::Vec2 d = q.p - p.p;
    if (periodic) {
      d.x -= width_ * std::round(d.x / width_);
      d.y -= height_ * std::round(d.y / height_);
    }
    const double r2 = dot(d, d);
    if (r2 >= max2) return;
    const auto bin = static_cast<std::size_t>(std::sqrt(r2) * inv_width);
    if (bin < bins) current_.pair_counts[pair_index(p.species, q.species) * bins + bin] += 1.0;
  };
  // Cells at least rdf_max wide: every pair within rdf_max lies in one cell or two neighbours.
  const int nx = std::max(1, static_cast<int>(width_ / rdf_max_)), ny = std::max(1, static_cast<int>(height_ / rdf_max_));
  if (periodic && (nx < 3 || ny < 3)) {  // a neighbour would be met twice around the box: all pairs
    for (std::size_t i = 0; i < items.size(); ++i)
      for (std::size_t j = i + 1; j < items.size(); ++j) count(items[i], items[j]);
    return;
  }
  auto cell_of = [&](sim::Vec2 p) {
    const int cx = std::clamp(static_cast<int>(p.x / width_ * nx), 0, nx - 1);
    const int cy = std::clamp(static_cast<int>(p.y / height_ * ny), 0, ny - 1);
    return cy * nx + cx;
  };
  std::vector<std::uint32_t> start(static_cast<std::size_t>(nx * ny) + 1, 0), order(items.size());
  for (const Item& it : items) ++start[static_cast<std::size_t>(cell_of(it.p)) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < items.size(); ++i) order[fill[static_cast<std::size_t>(cell_of(items[i].p))]++] = static_cast<std::uint32_t>(i);
  // Each cell with itself and four of its neighbours (a half stencil): every pair once.
  constexpr int kHalf[4][2] = {{1, 0}, {-1, 1}, {0, 1}, {1, 1}};
  for (int cy = 0; cy < ny; ++cy)
    for (int cx = 0; cx < nx; ++cx) {
      const std::size_t c = static_cast<std::size_t>(cy * nx + cx);
      for (std::uint32_t i = start[c]; i < start[c + 1]; ++i)
        for (std::uint32_t j = i + 1; j < start[c + 1]; ++j) count(items[order[i]], items[order[j]]);
      for (const auto& off : kHalf) {
        int ox = cx + off[0], oy = cy + off[1];
        if (periodic) ox = (ox + nx) % nx, oy = (oy + ny) % ny;
        else if (ox < 0 || ox >= nx || oy >= ny) continue;
        const std::size_t o = static_cast<std::size_t>(oy * nx + ox);
        for (std::uint32_t i = start[c]; i < start[c + 1]; ++i)
          for (std::uint32_t j = start[o]; j < start[o + 1]; ++j) count(items[order[i]], items[order[j]]);
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
