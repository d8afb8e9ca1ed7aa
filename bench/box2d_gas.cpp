// SPDX-License-Identifier: MIT
//
// box2d_gas: the walled disc gas of turtlegas's benchmarks run by Box2D 2.4 (Debian's
// libbox2d-dev), what a game-physics user would pick instead of an exact engine. It starts from
// the very state turtlegas starts from and prints one JSON line of cost and error figures, for
// bench/run_accuracy.sh (error against cost) and bench/run_peers.sh (body-steps per CPU-second
// beside turtlegas's step mode).
//
//   box2d_gas START.sph --dt DT (--until T | --steps S) [--reference REF.sph --horizon H]
//             [--wall-segment METRES] [--iterations VEL,POS] [--no-ccd] [--min-cpu S] [--name TEXT]
//
// START.sph is the start as the EDMD peers read it: N, then the box "Lx Ly", then one line per disc
// "a x y radius vx vy" (bench/peers_bench.py and bench/accuracy_bench write it; exact doubles,
// rounded to Box2D's floats here). The box [0, Lx] x [0, Ly] gets walls: a chain loop cut into
// segments of about --wall-segment metres (default 5; 0: four two-sided edges, one per side, which
// Box2D's broad phase handles badly at large N). Discs: dynamic circles, density 1, friction 0,
// restitution 1 with restitutionThreshold 0 (every approaching contact bounces), no damping, no
// sleeping. Box2D's solver: --iterations (default 8,3, its usual setting), continuous collision on
// (its default; --no-ccd turns it off).
//
// Timed: every Step() by this thread's CPU clock (and the wall clock), building the world not.
// The first step builds every broad-phase pair (as turtlegas's World constructor makes every first
// prediction, untimed), so cpu_per_sim_second and body_steps_per_cpu_second leave it out; it is
// reported as first_step_cpu_seconds. --min-cpu S repeats the whole run (the same bits each time)
// until the CPU time adds up to S, at most 20 runs, and keeps the fastest, as accuracy_bench does.
//
// With --reference REF.sph (the exact trajectory's state at time H, same discs in the same order)
// and --horizon H (a whole number of steps), the positions after round(H / dt) steps are compared
// with it: max_position_error and rms_position_error over the discs. energy_error is
// |E(T) - E(0)| / E(0) of the kinetic energy, in double from Box2D's float velocities, E(0) after
// they were rounded to floats.
#include <box2d/box2d.h>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Disc {
  double x, y, r, vx, vy;
};

struct Start {
  double width = 0.0, height = 0.0;
  std::vector<Disc> discs;
};

Start read_sph(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot open");
  Start s;
  std::size_t n = 0;
  if (!(in >> n >> s.width >> s.height) || n == 0 || !(s.width > 0.0) || !(s.height > 0.0))
    throw std::invalid_argument(path + ": expected N, then the box 'Lx Ly' (the EDMD peers' .sph)");
  s.discs.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::string type;
    Disc& d = s.discs[i];
    if (!(in >> type >> d.x >> d.y >> d.r >> d.vx >> d.vy))
      throw std::invalid_argument(path + ": disc " + std::to_string(i) + " is not 'a x y radius vx vy'");
  }
  return s;
}

struct Options {
  std::string start, reference, name;
  double dt = 0.0, until = 0.0, horizon = 0.0, wall_segment = 5.0, min_cpu = 0.0;
  long long steps = 0;
  int vel_iterations = 8, pos_iterations = 3;
  bool ccd = true;
};

[[noreturn]] void usage(const std::string& message) {
  throw std::invalid_argument(message +
                              "\nusage: box2d_gas START.sph --dt DT (--until T | --steps S) [--reference REF.sph "
                              "--horizon H] [--wall-segment METRES] [--iterations VEL,POS] [--no-ccd] [--min-cpu S] [--name TEXT]");
}

double number(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  double x = 0.0;
  try {
    x = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(x) || x < 0.0)
    usage(option + " needs a number >= 0, got '" + text + "'");
  return x;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    auto value = [&]() -> std::string {
      if (k + 1 >= argc) usage(arg + " needs a value");
      return argv[++k];
    };
    if (arg == "--dt") o.dt = number(arg, value());
    else if (arg == "--until") o.until = number(arg, value());
    else if (arg == "--steps") o.steps = std::llround(number(arg, value()));
    else if (arg == "--reference") o.reference = value();
    else if (arg == "--horizon") o.horizon = number(arg, value());
    else if (arg == "--wall-segment") o.wall_segment = number(arg, value());
    else if (arg == "--no-ccd") o.ccd = false;
    else if (arg == "--min-cpu") o.min_cpu = number(arg, value());
    else if (arg == "--name") o.name = value();
    else if (arg == "--iterations") {
      const std::string v = value();
      const auto comma = v.find(',');
      if (comma == std::string::npos) usage("--iterations takes VEL,POS, got '" + v + "'");
      o.vel_iterations = static_cast<int>(number(arg, v.substr(0, comma)));
      o.pos_iterations = static_cast<int>(number(arg, v.substr(comma + 1)));
    } else if (!arg.empty() && arg[0] == '-') usage("unknown option '" + arg + "'");
    else if (o.start.empty()) o.start = arg;
    else usage("one start file only, got a second: '" + arg + "'");
  }
  if (o.start.empty()) usage("no start file given");
  if (!(o.dt > 0.0)) usage("--dt is required and must be > 0");
  if ((o.until > 0.0) == (o.steps > 0)) usage("give one of --until T or --steps S");
  if (o.reference.empty() != !(o.horizon > 0.0)) usage("--reference and --horizon go together");
  return o;
}

void set_elastic(b2FixtureDef& fd) {
  fd.friction = 0.0f;
  fd.restitution = 1.0f;
  fd.restitutionThreshold = 0.0f;  // bounce however slowly the contact approaches
}

void add_walls(b2World& world, float w, float h, double segment) {
  b2BodyDef bd;  // static
  b2Body* walls = world.CreateBody(&bd);
  if (segment <= 0.0) {
    const b2Vec2 c[4] = {b2Vec2(0, 0), b2Vec2(w, 0), b2Vec2(w, h), b2Vec2(0, h)};
    for (int i = 0; i < 4; ++i) {
      b2EdgeShape e;
      e.SetTwoSided(c[i], c[(i + 1) % 4]);
      b2FixtureDef fd;
      fd.shape = &e;
      set_elastic(fd);
      walls->CreateFixture(&fd);
    }
    return;
  }
  // Clockwise, so that the chain's one-sided normals point into the box.
  const b2Vec2 c[4] = {b2Vec2(0, 0), b2Vec2(0, h), b2Vec2(w, h), b2Vec2(w, 0)};
  std::vector<b2Vec2> vs;
  for (int side = 0; side < 4; ++side) {
    const b2Vec2 a = c[side], b = c[(side + 1) % 4];
    const double length = std::hypot(b.x - a.x, b.y - a.y);
    const int k = std::max(1, static_cast<int>(std::ceil(length / segment)));
    for (int j = 0; j < k; ++j) {
      const float t = static_cast<float>(j) / static_cast<float>(k);
      vs.emplace_back(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y));
    }
  }
  b2ChainShape chain;
  chain.CreateLoop(vs.data(), static_cast<int>(vs.size()));
  b2FixtureDef fd;
  fd.shape = &chain;
  set_elastic(fd);
  walls->CreateFixture(&fd);
}

struct Counter : b2ContactListener {
  long long ball_ball = 0, ball_wall = 0;
  void BeginContact(b2Contact* c) override {
    const bool wall = c->GetFixtureA()->GetBody()->GetType() == b2_staticBody ||
                      c->GetFixtureB()->GetBody()->GetType() == b2_staticBody;
    ++(wall ? ball_wall : ball_ball);
  }
};

/// A number for the JSON line, or null when it was not measured (< 0).
std::string json_or_null(double x) {
  if (x < 0.0) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

double kinetic_energy(const std::vector<b2Body*>& bodies) {
  double e = 0.0;
  for (const b2Body* b : bodies) {
    const b2Vec2 u = b->GetLinearVelocity();
    const double w = b->GetAngularVelocity();
    e += 0.5 * b->GetMass() * (double(u.x) * u.x + double(u.y) * u.y) + 0.5 * b->GetInertia() * w * w;
  }
  return e;
}

/// What one simulation did.
struct Result {
  double cpu = 0.0, wall = 0.0, first_cpu = 0.0;  ///< steps after the first; the first alone
  double e0 = 0.0, e1 = 0.0;
  double max_err = -1.0, rms_err = -1.0;  ///< at the horizon; < 0: not measured
  long long escaped = 0;
  Counter counter;
};

Result simulate(const Options& o, const Start& start, const Start& reference, long long steps, long long horizon_step) {
  const std::size_t n = start.discs.size();
  Result res;
  b2World world(b2Vec2(0.0f, 0.0f));
  world.SetAllowSleeping(false);
  world.SetContinuousPhysics(o.ccd);
  world.SetContactListener(&res.counter);
  add_walls(world, static_cast<float>(start.width), static_cast<float>(start.height), o.wall_segment);
  std::vector<b2Body*> bodies;
  bodies.reserve(n);
  std::vector<b2CircleShape> shapes(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Disc& d = start.discs[i];
    b2BodyDef bd;
    bd.type = b2_dynamicBody;
    bd.position.Set(static_cast<float>(d.x), static_cast<float>(d.y));
    bd.linearVelocity.Set(static_cast<float>(d.vx), static_cast<float>(d.vy));
    bd.allowSleep = false;
    b2Body* b = world.CreateBody(&bd);
    shapes[i].m_radius = static_cast<float>(d.r);
    b2FixtureDef fd;
    fd.shape = &shapes[i];
    fd.density = 1.0f;
    set_elastic(fd);
    b->CreateFixture(&fd);
    bodies.push_back(b);
  }

  res.e0 = kinetic_energy(bodies);
  for (long long s = 1; s <= steps; ++s) {
    const double c0 = thread_cpu_seconds();
    const auto w0 = std::chrono::steady_clock::now();
    world.Step(static_cast<float>(o.dt), o.vel_iterations, o.pos_iterations);
    const double c = thread_cpu_seconds() - c0;
    if (s == 1) res.first_cpu = c;
    else {
      res.cpu += c;
      res.wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    }
    if (s == horizon_step) {
      double sum2 = 0.0;
      res.max_err = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        const b2Vec2 p = bodies[i]->GetPosition();
        const double e = std::hypot(double(p.x) - reference.discs[i].x, double(p.y) - reference.discs[i].y);
        res.max_err = std::max(res.max_err, e);
        sum2 += e * e;
      }
      res.rms_err = std::sqrt(sum2 / static_cast<double>(n));
    }
  }
  res.e1 = kinetic_energy(bodies);
  for (const b2Body* b : bodies) {
    const b2Vec2 p = b->GetPosition();
    if (!(p.x > 0.0f && p.y > 0.0f && p.x < float(start.width) && p.y < float(start.height))) ++res.escaped;
  }
  return res;
}

int run(int argc, char** argv) {
  const Options o = parse(argc, argv);
  const Start start = read_sph(o.start);
  const std::size_t n = start.discs.size();
  Start reference;
  if (!o.reference.empty()) {
    reference = read_sph(o.reference);
    if (reference.discs.size() != n) throw std::invalid_argument(o.reference + ": not the same number of discs as " + o.start);
  }
  const long long steps = o.steps > 0 ? o.steps : std::llround(o.until / o.dt);
  const long long horizon_step = o.horizon > 0.0 ? std::llround(o.horizon / o.dt) : -1;
  if (steps < 2) usage("the run needs at least two steps (the first is not timed)");
  if (horizon_step == 0 || horizon_step > steps || (horizon_step > 0 && std::abs(horizon_step * o.dt - o.horizon) > 1e-9 * o.horizon))
    usage("--horizon must be a whole number of steps, at most the run's length");

  // Repeated (the same bits: Box2D is deterministic) until the CPU time adds up to --min-cpu, at
  // most 20 runs; the fastest is kept, as accuracy_bench does for turtlegas.
  Result best;
  int repeats = 0;
  for (double total = 0.0; repeats < 20 && (repeats == 0 || total < o.min_cpu); ++repeats) {
    Result r = simulate(o, start, reference, steps, horizon_step);
    total += r.cpu + r.first_cpu;
    if (repeats == 0 || r.cpu < best.cpu) best = r;
  }

  const double timed_sim = static_cast<double>(steps - 1) * o.dt;
  const Result& r = best;
  std::printf("{\"scene\": \"walled\", \"code\": \"box2d\", \"box2d_version\": \"%d.%d.%d\", \"world_file\": \"%s\", \"N\": %zu, "
              "\"width\": %.17g, \"height\": %.17g, \"mode\": \"box2d\", \"dt\": %.17g, \"steps\": %lld, "
              "\"sim_seconds\": %.17g, \"repeats\": %d, \"cpu_seconds\": %.6g, \"wall_seconds\": %.6g, "
              "\"first_step_cpu_seconds\": %.6g, \"cpu_per_sim_second\": %.6g, \"body_steps_per_cpu_second\": %.6g, "
              "\"energy_start\": %.17g, \"energy_end\": %.17g, \"energy_drift\": %.6g, \"energy_error\": %.6g, "
              "\"contacts_begun\": %lld, \"ball_ball_begun\": %lld, \"ball_wall_begun\": %lld, \"escaped\": %lld, "
              "\"horizon\": %.17g, \"max_position_error\": %s, \"rms_position_error\": %s, \"wall_segment\": %g, "
              "\"iterations\": [%d, %d], \"ccd\": %s}\n",
              b2_version.major, b2_version.minor, b2_version.revision, o.name.empty() ? o.start.c_str() : o.name.c_str(),
              n, start.width, start.height, o.dt, steps, static_cast<double>(steps) * o.dt, repeats, r.cpu, r.wall,
              r.first_cpu, r.cpu / timed_sim, r.cpu > 0.0 ? static_cast<double>(steps - 1) * n / r.cpu : 0.0, r.e0,
              r.e1, (r.e1 - r.e0) / r.e0, std::abs(r.e1 - r.e0) / r.e0, r.counter.ball_ball + r.counter.ball_wall,
              r.counter.ball_ball, r.counter.ball_wall, r.escaped, o.horizon, json_or_null(r.max_err).c_str(),
              json_or_null(r.rms_err).c_str(), o.wall_segment, o.vel_iterations, o.pos_iterations,
              o.ccd ? "true" : "false");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "box2d_gas: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "box2d_gas: %s\n", e.what());
    return 1;
  }
}
