// SPDX-License-Identifier: MIT
// gas3d_bench: the 3-D engine on a periodic hard-sphere gas (sim/gas3d.hpp: fcc start, diameter 1,
// kT = 1), the peer's benchmark (docs/performance.md, "3-D"). Usage:
//   gas3d_bench K ETA COLLISIONS [WARMUP]    N = 4 K^3 spheres; WARMUP collisions untimed (default N * 10)
// Prints one JSON line: n, eta, collisions, events, cpu_seconds of the timed part, collisions per
// CPU-second, events per collision, Z from the collision virial.
#include <cstdio>
#include <cstdlib>
#include <ctime>

#include "turtlegas/sim/gas3d.hpp"

namespace {
double cpu_now() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: gas3d_bench K ETA COLLISIONS [WARMUP]\n");
    return 2;
  }
  const int k = std::atoi(argv[1]);
  const double eta = std::atof(argv[2]);
  const double collisions = std::atof(argv[3]);
  turtlegas::sim::World3 w(turtlegas::sim::fcc_gas3(k, eta, 1));
  const double n = static_cast<double>(w.sphere_count());
  const double warmup = argc > 4 ? std::atof(argv[4]) : 10 * n;
  // Time steps of about 0.2 collisions per sphere between calls.
  const double chunk = 0.2 / (n > 0 ? 1.0 : 1.0);
  while (static_cast<double>(w.collisions()) < warmup) w.advance_to(w.time() + chunk);
  const double c0 = static_cast<double>(w.collisions()), e0 = static_cast<double>(w.events());
  const double v0 = w.virial_sum(), t0 = w.time(), cpu0 = cpu_now();
  while (static_cast<double>(w.collisions()) < c0 + collisions) w.advance_to(w.time() + chunk);
  const double cpu = cpu_now() - cpu0;
  const double dc = static_cast<double>(w.collisions()) - c0, de = static_cast<double>(w.events()) - e0;
  std::printf("{\"n\": %.0f, \"eta\": %g, \"collisions\": %.0f, \"events\": %.0f, \"cpu_seconds\": %.4f, "
              "\"collisions_per_cpu_second\": %.0f, \"events_per_collision\": %.3f, \"z\": %.4f, "
              "\"max_contact_error\": %.3g}\n",
              n, eta, dc, de, cpu, dc / cpu, de / dc,
              turtlegas::sim::compressibility(w, w.virial_sum() - v0, w.time() - t0), w.max_contact_error());
  return 0;
}
