// SPDX-License-Identifier: MIT
// ray_bench: ray casts per second (World::cast_ray) in a walled room of N still discs, as lidars of
// 360 rays from points between the discs (docs/performance.md, "Ray casts"). One JSON line: the
// scene, the rays cast, CPU seconds, rays per CPU second, the fraction that hit and their mean
// distance, and a checksum of the distances (the same on every run of the same arguments).
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "turtlegas/sim/ray_cast.hpp"
#include "turtlegas/sim/world.hpp"

namespace {

using turtlegas::sim::Vec2;

int body(int argc, char** argv) {
  namespace sim = turtlegas::sim;
  const turtlegas::bench::Usage usage(
      "ray_bench [--n N] [--phi F] [--radius R] [--rays K] [--range D] [--seed S] [--mode exact|step]");
  long long n = 10000, rays = 3600000, seed = 1;
  double phi = 0.1, radius = 2.0, range = 100.0;
  sim::Mode mode = sim::Mode::exact;
  if (!turtlegas::bench::for_each_option(argc, argv, usage, [&](const std::string& o, const std::string& v) {
        if (o == "--n") n = usage.whole(o, v, 1, 100000000);
        else if (o == "--phi") phi = usage.positive(o, v);
        else if (o == "--radius") radius = usage.positive(o, v);
        else if (o == "--rays") rays = v == "0" ? 0 : usage.whole(o, v, 0, 1000000000000LL);
        else if (o == "--range") range = usage.positive(o, v);
        else if (o == "--seed") seed = usage.whole(o, v, 1, 1LL << 62);
        else if (o == "--mode") mode = turtlegas::bench::mode_option(usage, v);
        else usage.error("unknown option " + o);
      }))
    return 0;
  if (!(phi < 0.7)) usage.error("--phi must be below 0.7");
  // The discs on a jittered square lattice (never overlapping), as the engine tests' random_gas.
  const double side = std::sqrt(static_cast<double>(n) * M_PI * radius * radius / phi);
  sim::WorldDef def;
  def.name = "ray_bench";
  def.arena.width = def.arena.height = side;
  def.arena.boundary = sim::Boundary::walls;
  std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
  auto uniform = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  const auto per_row = static_cast<long long>(std::ceil(std::sqrt(static_cast<double>(n))));
  const double pitch = side / static_cast<double>(per_row);
  const double slack = std::max(0.0, pitch - 2.0 * radius) * 0.49;
  def.balls.reserve(static_cast<std::size_t>(n));
  for (long long i = 0; i < n; ++i) {
    const double x = (static_cast<double>(i % per_row) + 0.5) * pitch + (2 * uniform() - 1) * slack;
    const double y = (static_cast<double>(i / per_row) + 0.5) * pitch + (2 * uniform() - 1) * slack;
    def.balls.push_back({"b" + std::to_string(i), {x, y}, {0, 0}, radius, 1.0, 0.0, {}});
  }
  const sim::World world(std::move(def), mode);
  // Lidar origins on the lattice's corners: at least 0.98 r + 0.01 pitch from every centre along
  // each axis, so never inside a disc.
  std::vector<Vec2> dirs(360);
  for (int k = 0; k < 360; ++k) dirs[static_cast<std::size_t>(k)] = {std::sin(k * M_PI / 180.0), std::cos(k * M_PI / 180.0)};
  sim::Ray ray;
  ray.range = range;
  long long hits = 0;
  double sum = 0.0;
  const double t0 = turtlegas::bench::thread_cpu_seconds();
  for (long long done = 0; done < rays;) {
    ray.origin = {static_cast<double>(1 + static_cast<long long>(uniform() * static_cast<double>(per_row - 1))) * pitch,
                  static_cast<double>(1 + static_cast<long long>(uniform() * static_cast<double>(per_row - 1))) * pitch};
    for (std::size_t k = 0; k < dirs.size() && done < rays; ++k, ++done) {
      ray.dir = dirs[k];
      const sim::RayHit h = world.cast_ray(ray);
      if (h.hit()) {
        ++hits;
        sum += h.distance;
      }
    }
  }
  const double cpu = turtlegas::bench::thread_cpu_seconds() - t0;
  std::cout << std::setprecision(6) << "{\"bench\": \"ray_bench\", \"n\": " << n << ", \"phi\": " << phi
            << ", \"radius\": " << radius << ", \"side\": " << side << ", \"cell\": " << world.cell_size()
            << ", \"range\": " << range << ", \"rays\": " << rays << ", \"cpu_s\": " << cpu
            << ", \"rays_per_cpu_s\": " << (cpu > 0 ? static_cast<double>(rays) / cpu : 0.0)
            << ", \"hit_fraction\": " << (rays > 0 ? static_cast<double>(hits) / static_cast<double>(rays) : 0.0)
            << ", \"mean_hit_distance\": " << (hits > 0 ? sum / static_cast<double>(hits) : 0.0)
            << std::setprecision(17) << ", \"checksum\": " << sum << "}\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return turtlegas::bench::run_with_exit_codes("ray_bench", body, argc, argv); }
