// SPDX-License-Identifier: MIT
// field_toi_bench: the cost of each field time-of-impact function (field_toi.hpp), in nanoseconds
// per call on random scenes like those of tests/sim/field_toi_test.cpp, beside today's toi.hpp
// functions on straight and parabolic flights. Thread CPU time over batches (the median of
// `rounds` batches), and the tail (99.9th percentile, max) from timing each call on its own.
//
//   field_toi_bench [calls per batch, default 20000] [rounds, default 5]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "turtlegas/sim/field_toi.hpp"
#include "turtlegas/sim/seeded_rng.hpp"

using namespace turtlegas::sim;

namespace {

using Rng = SeededRng;  // the field tests' generator (tests/sim/field_oracle.hpp)

double random_w(Rng& rng) { return rng.sign() * rng.log_uniform(1e-6, 1e6) * rng.log_uniform(1e-8, 1e6); }

// One benchmark: a vector of prepared calls, each returning a time (summed so nothing is elided).
struct Case {
  std::string name;
  std::vector<std::function<double()>> calls;
};

Case rotating_pair(Rng& rng, int n) {
  Case c{"disc-disc, equal q/m (closed form)", {}};
  for (int k = 0; k < n; ++k) {
    const double w = random_w(rng), speed = rng.log_uniform(1e-3, 1e3), rho = speed / std::abs(w);
    const double sigma = rho * rng.log_uniform(1e-2, 1e2);
    const Vec2 dv = speed * rng.direction(), r0 = rng.direction_then([&] { return (sigma * 1.000001 + rho * rng.uniform(0, 2.5)); });
    const double H = 1.5 * gyration_period(w);
    c.calls.push_back([=] { return toi_field_disc_disc_rotating(r0, dv, w, sigma, H); });
  }
  return c;
}

Case general_pair(Rng& rng, int n, bool with_turtle) {
  Case c{with_turtle ? "disc-disc, charged ball vs turtle (bracketed)" : "disc-disc, unequal q/m (bracketed)", {}};
  for (int k = 0; k < n; ++k) {
    const double bz = rng.sign() * rng.log_uniform(1e-8, 1e6);
    const double qm1 = with_turtle ? 0.0 : rng.sign() * rng.log_uniform(1e-6, 1e6);
    const double qm2 = rng.sign() * rng.log_uniform(1e-6, 1e6);
    const double wmax = std::max(std::abs(qm1 * bz), std::abs(qm2 * bz));
    const double tau = rng.log_uniform(0.3, 3) / wmax, speed = 1.0 / tau;
    const Vec2 e = rng.direction_then([&] { return (k % 2 ? rng.uniform(0, 2) * speed * std::abs(bz) : 0.0); });
    const FieldFlight f1 = with_turtle ? FieldFlight{rng.direction_then([&] { return rng.uniform(0, 2) * speed; }), {}, 0.0}
                                       : FieldFlight{rng.direction_then([&] { return rng.uniform(0, 2) * speed; }), qm1 * e, qm1 * bz};
    const FieldFlight f2{rng.direction_then([&] { return rng.uniform(0, 2) * speed; }), qm2 * e, qm2 * bz};
    const double sigma = rng.uniform(0.2, 1.5);
    const Vec2 r0 = rng.direction_then([&] { return (sigma * 1.000001 + rng.uniform(0.01, 1.5)); });
    const double H = tau * rng.uniform(1, 8);
    c.calls.push_back([=] { return toi_field_disc_disc(r0, f1, f2, sigma, H); });
  }
  return c;
}

// kind 0: drift across the wall (monotone pieces), 1: along it (closed form), 2: none.
Case wall(Rng& rng, int n, int kind) {
  const char* names[3] = {"disc-segment, drift across (pieces)", "disc-segment, drift along (closed form)",
                          "disc-segment, no drift (closed form)"};
  Case c{names[kind], {}};
  for (int k = 0; k < n; ++k) {
    const double w = random_w(rng), tau = rng.log_uniform(0.3, 3) / std::abs(w), speed = 1.0 / tau;
    const Vec2 from{rng.uniform(-2, 2), rng.uniform(-2, 2)};
    const Segment s = make_segment(from, from + rng.direction_then([&] { return rng.uniform(0.5, 4); }));
    Vec2 a = rng.direction_then([&] { return rng.uniform(0, 2) * speed * std::abs(w); });
    if (kind == 1) a = rng.uniform(-2, 2) * speed * std::abs(w) * s.n;
    if (kind == 2) a = {};
    const FieldFlight f{rng.direction_then([&] { return rng.uniform(0.2, 2) * speed; }), a, w};
    const double radius = rng.uniform(0.05, 0.8);
    Vec2 rel;
    for (;;) {
      const double across = rng.uniform(-2, 2), along = rng.uniform(-0.5, 1.5);  // this order: see Rng
      rel = (s.len * along) * s.u + across * s.n;
      const double foot = std::clamp(dot(rel, s.u), 0.0, s.len);
      if (norm(rel - foot * s.u) > radius * 1.000001) break;
    }
    const double H = tau * rng.uniform(2, 12);
    c.calls.push_back([=] { return toi_field_disc_segment(rel, f, s, radius, H); });
  }
  return c;
}

Case point(Rng& rng, int n, bool drift) {
  Case c{drift ? "disc-point, with drift (bracketed)" : "disc-point, no drift (closed form)", {}};
  for (int k = 0; k < n; ++k) {
    const double w = random_w(rng), tau = rng.log_uniform(0.3, 3) / std::abs(w), speed = 1.0 / tau;
    const Vec2 a = rng.direction_then([&] { return (drift ? rng.uniform(0.05, 2) * speed * std::abs(w) : 0.0); });
    const FieldFlight f{rng.direction_then([&] { return rng.uniform(0.2, 2) * speed; }), a, w};
    const double radius = rng.uniform(0.1, 1);
    const Vec2 rel = rng.direction_then([&] { return (radius * 1.000001 + rng.uniform(0, 3)); });
    const double H = tau * rng.uniform(2, 12);
    c.calls.push_back([=] { return toi_field_disc_point(rel, f, radius, H); });
  }
  return c;
}

Case cell_exit(Rng& rng, int n, bool drift) {
  Case c{drift ? "cell exit, drift along the axis (pieces)" : "cell exit, no drift along it (closed form)", {}};
  for (int k = 0; k < n; ++k) {
    const double w = random_w(rng), tau = rng.log_uniform(0.3, 3) / std::abs(w), speed = 1.0 / tau;
    const int axis = k % 2;
    Vec2 a = rng.direction_then([&] { return rng.uniform(0.05, 2) * speed * std::abs(w); });
    if (!drift) (axis == 0 ? a.y : a.x) = 0.0;
    const FieldFlight f{rng.direction_then([&] { return rng.uniform(0.2, 2) * speed; }), a, w};
    const double x = rng.uniform(-1, 1), lo = x - rng.uniform(0.05, 2), hi = x + rng.uniform(0.05, 2);
    const double H = tau * rng.uniform(2, 12);
    c.calls.push_back([=] { return field_axis_exit(x, f, axis, lo, hi, H).t; });
  }
  return c;
}

// Today's functions, for scale.
Case today(Rng& rng, int n, int which) {
  const char* names[3] = {"toi_disc_disc (straight)", "toi_disc_segment (parabola)", "toi_disc_point_accel (quartic)"};
  Case c{names[which], {}};
  for (int k = 0; k < n; ++k) {
    const Vec2 r0 = rng.direction_then([&] { return rng.uniform(1.2, 4); }), v = rng.direction_then([&] { return rng.uniform(0.2, 2); });
    const Vec2 a = rng.direction_then([&] { return rng.uniform(0.1, 2); });
    const Segment s = make_segment({-2, -1}, {2, -1});
    if (which == 0) c.calls.push_back([=] { return toi_disc_disc(r0, v, 1.0); });
    if (which == 1) c.calls.push_back([=] { return toi_disc_segment(r0 - s.p1, v, a, s, 0.5); });
    if (which == 2) c.calls.push_back([=] { return toi_disc_point_accel(r0, v, a, 1.0, 20.0); });
  }
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::stoi(argv[1]) : 20000;
  const int rounds = argc > 2 ? std::stoi(argv[2]) : 5;
  Rng rng(20261216);
  std::vector<Case> cases;
  cases.push_back(today(rng, n, 0));
  cases.push_back(today(rng, n, 1));
  cases.push_back(today(rng, n, 2));
  cases.push_back(rotating_pair(rng, n));
  cases.push_back(general_pair(rng, n, false));
  cases.push_back(general_pair(rng, n, true));
  for (int kind = 0; kind < 3; ++kind) cases.push_back(wall(rng, n, kind));
  cases.push_back(point(rng, n, false));
  cases.push_back(point(rng, n, true));
  cases.push_back(cell_exit(rng, n, false));
  cases.push_back(cell_exit(rng, n, true));
  std::printf("%-48s %10s %10s %10s %8s\n", "function", "ns/call", "p99.9 ns", "max ns", "hits");
  double sink = 0.0;
  for (const Case& c : cases) {
    std::vector<double> batch;
    int hits = 0;
    for (int r = 0; r < rounds; ++r) {
      const double t0 = turtlegas::bench::thread_cpu_seconds();
      for (const auto& call : c.calls) {
        const double t = call();
        sink += t == kNever ? 0.0 : t;
        hits += r == 0 && t != kNever;
      }
      batch.push_back((turtlegas::bench::thread_cpu_seconds() - t0) / static_cast<double>(c.calls.size()) * 1e9);
    }
    std::sort(batch.begin(), batch.end());
    std::vector<double> each;
    each.reserve(c.calls.size());
    for (const auto& call : c.calls) {
      const auto t0 = std::chrono::steady_clock::now();
      sink += call() == kNever ? 0.0 : 1.0;
      each.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count());
    }
    std::sort(each.begin(), each.end());
    std::printf("%-48s %10.0f %10.0f %10.0f %7.0f%%\n", c.name.c_str(), batch[batch.size() / 2],
                each[each.size() * 999 / 1000], each.back(), 100.0 * hits / static_cast<double>(c.calls.size()));
  }
  std::fprintf(stderr, "(checksum %g)\n", sink);
  return 0;
}
