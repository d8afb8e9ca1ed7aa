// SPDX-License-Identifier: MIT
// Motion observables of the Observer (observables.hpp): unwrapped coordinates, the mean-squared
// displacement MSD(tau) and the velocity autocorrelation C(tau) = <v(0) . v(tau)> over the sample
// grid of each window, every sample a time origin, and the diffusion coefficient from each: the
// Einstein relation MSD = 2 d D tau and Green-Kubo's D = (1/d) int_0^tau C, d = 2 or 3. In a
// periodic arena positions and velocities are taken about the centre of mass's, which moves
// uniformly there (the total momentum is conserved); behind walls in the lab frame.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "turtlegas/formats/observables.hpp"

namespace turtlegas::formats {
namespace {

nlohmann::json block_of(const std::vector<double>& x) {
  const double n = static_cast<double>(x.size());
  const double m = x.empty() ? 0.0 : std::accumulate(x.begin(), x.end(), 0.0) / n;
  double ss = 0.0;
  for (double v : x) ss += (v - m) * (v - m);
  return {{"mean", m}, {"error", x.size() > 1 ? std::sqrt(ss / (n * (n - 1.0))) : 0.0}};
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

double Observer::unwrap_step() const {
  // No ball is faster than sqrt(2 K / m_min), K the kinetic energy of all of them (conserved, or
  // lost to restitution, in a gas without fields). Stopping before any ball can cross a quarter of
  // the shortest side keeps the nearest image of each displacement the true one, with a factor of
  // two to spare for a field's work between stops.
  double k = 0.0, m_min = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < count(); ++i) {
    if (!alive(i)) continue;
    const sim::Vec3 v = vel(i);
    k += 0.5 * mass(i) * dot(v, v);
    m_min = std::min(m_min, mass(i));
  }
  if (!(k > 0.0)) return std::numeric_limits<double>::infinity();
  double side = std::min(size_.x, size_.y);
  if (dims_ == 3) side = std::min(side, size_.z);
  return 0.25 * side / std::sqrt(2.0 * k / m_min);
}

void Observer::unwrap() {
  if (boundary_ != sim::Boundary::periodic) {  // coordinates are not wrapped: taken as they are
    for (std::size_t i = 0; i < count(); ++i) unwrapped_[i] = pos(i);
    return;
  }
  // The unwrapped position is the wrapped one plus whole periods, counted: it does not depend on
  // where the run stopped on the way (the CLI and the Python module stop at different times, and a
  // sum of displacements would differ in its last digits).
  for (std::size_t i = 0; i < count(); ++i) {
    const sim::Vec3 p = pos(i);
    const sim::Vec3 d = p - last_pos_[i];
    for (int k = 0; k < dims_; ++k) images_[i][k] -= std::round(d[k] / size_[k]);
    unwrapped_[i] = p;
    for (int k = 0; k < dims_; ++k) unwrapped_[i][k] += images_[i][k] * size_[k];
    last_pos_[i] = p;
  }
}

void Observer::start_motion() {
  unwrapped_.resize(count());
  last_pos_.resize(count());
  images_.assign(count(), sim::Vec3{});
  for (std::size_t i = 0; i < count(); ++i) unwrapped_[i] = last_pos_[i] = pos(i);
  frame_pos_.clear();
  frame_vel_.clear();
  sample_motion();
}

void Observer::sample_motion() {
  unwrap();
  const bool periodic = boundary_ == sim::Boundary::periodic;
  sim::Vec3 r{}, p{};
  double m = 0.0;
  for (std::size_t i = 0; i < count(); ++i) {
    if (!alive(i)) continue;
    r += mass(i) * unwrapped_[i];
    p += mass(i) * vel(i);
    m += mass(i);
  }
  const sim::Vec3 rc = periodic && m > 0.0 ? sim::Vec3{r.x / m, r.y / m, r.z / m} : sim::Vec3{}, vc = periodic && m > 0.0 ? sim::Vec3{p.x / m, p.y / m, p.z / m} : sim::Vec3{};
  std::vector<sim::Vec3> ps(count()), vs(count());
  for (std::size_t i = 0; i < count(); ++i) {
    ps[i] = alive(i) ? unwrapped_[i] - rc : sim::Vec3{kNaN, kNaN, kNaN};
    vs[i] = vel(i) - vc;
  }
  frame_pos_.push_back(std::move(ps));
  frame_vel_.push_back(std::move(vs));
}

void Observer::close_motion(Window& w) {
  // Frames 0..samples: the window's start and its samples. Lag k pairs frame i with frame i + k.
  const std::size_t lags = frame_pos_.size(), S = species_.size();
  w.msd.assign((S + 1) * lags, 0.0);
  w.vacf.assign((S + 1) * lags, 0.0);
  std::vector<double> pairs((S + 1) * lags, 0.0);
  for (std::size_t k = 0; k < lags; ++k)
    for (std::size_t i = 0; i + k < lags; ++i) {
      const auto &p0 = frame_pos_[i], &p1 = frame_pos_[i + k], &v0 = frame_vel_[i], &v1 = frame_vel_[i + k];
      for (std::size_t b = 0; b < p0.size(); ++b) {
        if (std::isnan(p0[b].x) || std::isnan(p1[b].x)) continue;
        const sim::Vec3 d = p1[b] - p0[b];
        const double d2 = dot(d, d), c = dot(v0[b], v1[b]);
        for (std::size_t row : {std::size_t{0}, species_of_[b] + 1}) {
          w.msd[row * lags + k] += d2;
          w.vacf[row * lags + k] += c;
          pairs[row * lags + k] += 1.0;
        }
      }
    }
  for (std::size_t j = 0; j < pairs.size(); ++j)
    if (pairs[j] > 0.0) w.msd[j] /= pairs[j], w.vacf[j] /= pairs[j];
  // The last frame starts the next window.
  frame_pos_.erase(frame_pos_.begin(), frame_pos_.end() - 1);
  frame_vel_.erase(frame_vel_.begin(), frame_vel_.end() - 1);
}

void Observer::motion_results(nlohmann::json& out, nlohmann::json& summary) const {
  const std::size_t lags = static_cast<std::size_t>(opt_.samples) + 1, S = species_.size();
  const double step = opt_.window / opt_.samples;
  nlohmann::json tau = nlohmann::json::array();
  for (std::size_t k = 0; k < lags; ++k) tau.push_back(static_cast<double>(k) * step);
  // One row (all balls, or a species) of every window: the curves with block errors, D from the
  // MSD's least-squares slope over the second half of the lags (past the ballistic start, once a
  // window spans many collisions) and D from the trapezoidal integral of C over all of them.
  auto row_of = [&](std::size_t row, nlohmann::json& into) {
    std::vector<std::vector<double>> msd(lags), vacf(lags);
    std::vector<double> d_msd, d_gk;
    for (const Window& w : done_) {
      if (w.msd.size() != (S + 1) * lags) continue;
      const double* m = &w.msd[row * lags];
      const double* c = &w.vacf[row * lags];
      for (std::size_t k = 0; k < lags; ++k) msd[k].push_back(m[k]), vacf[k].push_back(c[k]);
      const std::size_t k0 = std::max<std::size_t>(1, lags / 2);
      double sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
      for (std::size_t k = k0; k < lags; ++k) {
        const double x = static_cast<double>(k) * step;
        sx += x, sy += m[k], sxx += x * x, sxy += x * m[k], n += 1.0;
      }
      const double slope = n > 1.0 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : sy / sx;
      d_msd.push_back(slope / (2.0 * dims_));  // MSD = 2 d D tau
      double integral = 0.0;
      for (std::size_t k = 0; k + 1 < lags; ++k) integral += 0.5 * (c[k] + c[k + 1]) * step;
      d_gk.push_back(integral / dims_);  // D = (1/d) int C
    }
    nlohmann::json mm = nlohmann::json::array(), me = nlohmann::json::array(), cm = nlohmann::json::array(),
                   ce = nlohmann::json::array();
    for (std::size_t k = 0; k < lags; ++k) {
      const nlohmann::json a = block_of(msd[k]), b = block_of(vacf[k]);
      mm.push_back(a["mean"]), me.push_back(a["error"]), cm.push_back(b["mean"]), ce.push_back(b["error"]);
    }
    into["msd"] = {{"lag", tau}, {"msd", mm}, {"error", me}};
    into["vacf"] = {{"lag", tau}, {"vacf", cm}, {"error", ce}};
    into["D_msd"] = block_of(d_msd);
    into["D_green_kubo"] = block_of(d_gk);
  };
  nlohmann::json all;
  row_of(0, all);
  out["msd"] = all["msd"];
  out["vacf"] = all["vacf"];
  summary["D_msd"] = all["D_msd"];
  summary["D_green_kubo"] = all["D_green_kubo"];
  nlohmann::json species = nlohmann::json::array();
  for (std::size_t s = 0; s < S; ++s) {
    std::vector<double> kT;
    for (const Window& w : done_)
      if (s < w.kT_species.size()) kT.push_back(w.kT_species[s] / std::max(w.samples, 1));
    nlohmann::json one = {{"radius", species_[s].radius}, {"mass", species_[s].mass}, {"count", species_[s].count},
                          {"kT", block_of(kT)}};
    row_of(s + 1, one);
    species.push_back(one);
  }
  out["species"] = species;
}

}  // namespace turtlegas::formats
