// SPDX-License-Identifier: MIT
// vec_bench: agent-steps per second of learn::VecWorld, N copies of a world stepped by T threads
// under random actions (docs/performance.md, "Vectorised worlds"). A timed step is what a
// learner's loop does: random actions for every turtle (VecWorld::sample_actions), one control
// step of every copy (physics, contacts, touch arcs, range rays, odometry) and the observations
// written into one contiguous float array (N, turtles, obs). One JSON line: the set-up, wall and
// CPU seconds, env-steps and agent-steps per wall second, and a checksum of the last observations
// (the same for any thread count).
#include <cstdint>
#include <ctime>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/learn/vec_world.hpp"

namespace {

double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

int body(int argc, char** argv) {
  namespace tl = turtlegas::learn;
  const turtlegas::bench::Usage usage(
      "vec_bench [--world W.json] [--worlds N] [--threads T] [--steps S] [--warmup K] [--seed S] "
      "[--actions velocity|wheels|logo] [--mode exact|step]");
  std::string file = "worlds/learn/swarm16.json";
  long long n = 64, threads = 1, steps = 200, warmup = 10, seed = 1;
  tl::VecWorldOptions options;
  if (!turtlegas::bench::for_each_option(argc, argv, usage, [&](const std::string& o, const std::string& v) {
        if (o == "--world") file = v;
        else if (o == "--worlds") n = usage.whole(o, v, 1, 10000000);
        else if (o == "--threads") threads = usage.whole(o, v, 1, 1024);
        else if (o == "--steps") steps = usage.whole(o, v, 1, 1000000000);
        else if (o == "--warmup") warmup = v == "0" ? 0 : usage.whole(o, v, 0, 1000000000);
        else if (o == "--seed") seed = usage.whole(o, v, 1, 1LL << 62);
        else if (o == "--mode") options.mode = turtlegas::bench::mode_option(usage, v);
        else if (o == "--actions") {
          if (v == "velocity") options.actions = tl::ActionKind::velocity;
          else if (v == "wheels") options.actions = tl::ActionKind::wheels;
          else if (v == "logo") options.actions = tl::ActionKind::logo;
          else usage.error("--actions takes velocity, wheels or logo, got '" + v + "'");
        } else usage.error("unknown option " + o);
      }))
    return 0;
  options.threads = static_cast<std::size_t>(threads);
  const turtlegas::turtle::Registry registry = turtlegas::controllers::builtin_registry();
  tl::VecWorld vec(turtlegas::world::load_scene(file, registry), static_cast<std::size_t>(n), options);
  const std::size_t agents = vec.size() * vec.turtle_count();
  std::vector<float> obs(agents * vec.obs_size());
  std::vector<float> act(agents * 2);
  std::vector<std::int32_t> logo(agents);
  std::vector<std::uint8_t> term(vec.size()), trunc(vec.size());
  const bool discrete = options.actions == tl::ActionKind::logo;
  auto one_step = [&] {
    if (discrete) {
      vec.sample_actions(logo);
      vec.step(logo, obs, term, trunc);
    } else {
      vec.sample_actions(act);
      vec.step(act, obs, term, trunc);
    }
  };
  vec.reset(static_cast<std::uint64_t>(seed), obs);
  for (long long k = 0; k < warmup; ++k) one_step();
  const double c0 = process_cpu_seconds();
  const auto w0 = std::chrono::steady_clock::now();
  for (long long k = 0; k < steps; ++k) one_step();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  const double cpu = process_cpu_seconds() - c0;
  double checksum = 0.0;
  for (float x : obs) checksum += x;
  std::uint64_t contacts = 0;
  for (std::size_t i = 0; i < vec.size(); ++i) contacts += vec.last_contacts(i);
  const double env_steps = static_cast<double>(n) * static_cast<double>(steps);
  std::cout << std::setprecision(6) << "{\"bench\": \"vec_bench\", \"world\": \"" << file << "\", \"worlds\": " << n
            << ", \"turtles\": " << vec.turtle_count() << ", \"obs_size\": " << vec.obs_size()
            << ", \"rays\": " << vec.layout().range_count << ", \"threads\": " << vec.thread_count()
            << ", \"steps\": " << steps << ", \"warmup\": " << warmup << ", \"wall_s\": " << wall << ", \"cpu_s\": " << cpu
            << ", \"ms_per_step\": " << 1e3 * wall / static_cast<double>(steps)
            << ", \"env_steps_per_s\": " << env_steps / wall
            << ", \"agent_steps_per_s\": " << env_steps * static_cast<double>(vec.turtle_count()) / wall
            << ", \"contacts_last_step\": " << contacts << std::setprecision(17) << ", \"checksum\": " << checksum << "}\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return turtlegas::bench::run_with_exit_codes("vec_bench", body, argc, argv); }
