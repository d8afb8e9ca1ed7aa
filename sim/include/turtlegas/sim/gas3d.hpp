// SPDX-License-Identifier: MIT
// The periodic hard-sphere gas that the 3-D equation-of-state test (tests/sim/world3d_eos_test.cpp)
// and the 3-D benchmark (bench/gas3d_bench.cpp) both start from: an fcc lattice of 4 k^3 spheres
// of diameter 1 at packing fraction eta, random velocities (seeded) of zero total momentum scaled
// to kT = 1 per unit mass. Here because tests/ and bench/ may not include each other.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

#include "turtlegas/sim/world3d.hpp"

namespace turtlegas::sim {

inline World3Def fcc_gas3(int k, double eta, std::uint64_t seed) {
  const double n = 4.0 * k * k * k;
  const double volume = n * (3.141592653589793 / 6.0) / eta;
  const double side = std::cbrt(volume), a = side / k;
  World3Def def;
  def.size = {side, side, side};
  def.boundary = Boundary3::periodic;
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double basis[4][3] = {{0.25, 0.25, 0.25}, {0.75, 0.75, 0.25}, {0.75, 0.25, 0.75}, {0.25, 0.75, 0.75}};
  Vec3 p;
  for (int x = 0; x < k; ++x)
    for (int y = 0; y < k; ++y)
      for (int z = 0; z < k; ++z)
        for (const auto& b : basis) {
          Sphere3Def s;
          s.pos = {(x + b[0]) * a, (y + b[1]) * a, (z + b[2]) * a};
          s.vel = {gauss(gen), gauss(gen), gauss(gen)};
          s.radius = 0.5;
          p += s.vel;
          def.spheres.push_back(s);
        }
  double ke = 0.0;
  for (auto& s : def.spheres) {
    s.vel -= (1.0 / n) * p;
    ke += 0.5 * norm2(s.vel);
  }
  const double scale = std::sqrt(1.5 * n / ke);
  for (auto& s : def.spheres) s.vel = scale * s.vel;
  return def;
}

/// Z = PV / NkT from the collision virial over a run of length t: 1 + sum / (2 KE t).
inline double compressibility(const World3& w, double virial, double t) {
  return 1.0 + virial / (2.0 * w.kinetic_energy() * t);
}

}  // namespace turtlegas::sim
