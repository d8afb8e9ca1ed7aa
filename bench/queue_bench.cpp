// SPDX-License-Identifier: MIT
// The event queue alone, in the classic "hold" model (Jones, CACM 1986): serve the earliest
// (key, id), give that id a new key a random interval later, repeat. Every event of exact mode does
// at least one hold (a cell crossing does exactly one; a collision re-keys both balls), so the
// cost of a hold times the events per collision is a floor on the cost of a collision that no
// change outside the queue can go below. The nodes sit 128 bytes apart, as in the engine's records
// (sim/src/engine.cpp, Record), so the queue touches memory as it does there.
//
//   queue_bench [--ids N] [--holds H] [--seed S]
//
// Prints one JSON line: ns per hold (the thread's CPU time), the same for a loop that only draws
// the random intervals (subtracted), and the latency of one dependent load of a random record among
// N (a pointer chase over a random cycle): what an event pays for its own record when nothing
// could be prefetched.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "event_queue.hpp"

using turtlegas::bench::thread_cpu_seconds;
using turtlegas::sim::detail::EventQueue;

namespace {

struct alignas(64) Record {
  char body_and_prediction[96];  // what the engine keeps beside the node
  EventQueue::Node node;
  double mass = 0.0;
};
static_assert(sizeof(Record) == 128);

}  // namespace

int main(int argc, char** argv) {
  std::size_t ids = 10000;
  std::size_t holds = 20'000'000;
  std::uint64_t seed = 272;
  for (int k = 1; k + 1 < argc; k += 2) {
    const std::string a = argv[k], v = argv[k + 1];
    if (a == "--ids") ids = static_cast<std::size_t>(std::stod(v));
    else if (a == "--holds") holds = static_cast<std::size_t>(std::stod(v));
    else if (a == "--seed") seed = std::stoull(v);
    else {
      std::cerr << "queue_bench: unknown option " << a << " (known: --ids, --holds, --seed)\n";
      return 2;
    }
  }
  if (ids < 2 || ids > 0xFFFFFFF0u || holds == 0) {
    std::cerr << "queue_bench: --ids must be in [2, 4e9) and --holds positive\n";
    return 2;
  }

  // Intervals as in a gas: each id's next event an exponential time later, mean 1 s for every id
  // (the rate only scales time; the calendar re-estimates its bucket width from the keys).
  std::mt19937_64 rng(seed);
  std::exponential_distribution<double> interval(1.0);

  std::vector<Record> records(ids);
  EventQueue q;
  q.reset(&records[0].node, sizeof(Record), ids);
  for (std::uint32_t i = 0; i < ids; ++i) q.set(i, interval(rng));
  // Warm up: a year or two of the calendar, so the bucket width has settled.
  for (std::size_t k = 0; k < 4 * ids; ++k) {
    const std::uint32_t i = q.top_id();
    q.set(i, q.top_key() + interval(rng));
  }

  double sink = 0.0;
  const double t0 = thread_cpu_seconds();
  for (std::size_t k = 0; k < holds; ++k) {
    const std::uint32_t i = q.top_id();
    q.set(i, q.top_key() + interval(rng));
  }
  const double t1 = thread_cpu_seconds();
  for (std::size_t k = 0; k < holds; ++k) sink += interval(rng);
  const double t2 = thread_cpu_seconds();

  // A random cycle through the records (Sattolo's shuffle), followed link by link.
  std::vector<std::uint32_t> order(ids);
  for (std::uint32_t i = 0; i < ids; ++i) order[i] = i;
  for (std::size_t i = ids - 1; i > 0; --i) std::swap(order[i], order[std::uniform_int_distribution<std::size_t>(0, i - 1)(rng)]);
  for (std::size_t i = 0; i < ids; ++i) records[order[i]].node.next = order[(i + 1) % ids];
  const std::size_t loads = std::max<std::size_t>(holds / 4, 4 * ids);
  std::uint32_t at = 0;
  const double t3 = thread_cpu_seconds();
  for (std::size_t k = 0; k < loads; ++k) at = records[at].node.next;
  const double t4 = thread_cpu_seconds();
  sink += at;

  const double hold_ns = (t1 - t0) * 1e9 / static_cast<double>(holds);
  const double load_ns = (t4 - t3) * 1e9 / static_cast<double>(loads);
  const double draw_ns = (t2 - t1) * 1e9 / static_cast<double>(holds);
  std::printf("{\"bench\":\"queue\",\"ids\":%zu,\"holds\":%zu,\"ns_per_hold\":%.2f,\"ns_per_draw\":%.2f,"
              "\"ns_per_hold_less_draw\":%.2f,\"ns_per_random_record\":%.2f,\"queue_bytes_per_id\":%.1f,"
              "\"sink\":%.3f}\n",
              ids, holds, hold_ns, draw_ns, hold_ns - draw_ns, load_ns,
              static_cast<double>(q.memory_bytes()) / static_cast<double>(ids), sink > 0.0 ? 1.0 : 0.0);
  return 0;
}
