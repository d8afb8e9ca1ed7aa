// enki_epuck: bench/epuck_bench.cpp's e-puck swarm in Enki (Debian's libenki-dev), as a peer to
// measure turtlegas against (issue 34 §6). N Enki::EPuck robots on a lattice 20 units apart in a
// square walled arena (Enki::World(w, h)), headings spread by the golden angle, each running the
// obstacle avoider of controllers/epuck_swarm.cpp on its eight IR sensors and two wheels in its
// controlStep. Control step dt = 0.1 s, one physics step per control step. One thread.
//
//   enki_epuck N STEPS [--sensors ir|none|default]
//
// The robot: EPuck(CAPABILITY_NONE), then its eight infrared sensors added as local interactions,
// so that it has the IR ring alone. EPuck's default, CAPABILITY_BASIC_SENSORS (0x1), also switches
// on the scanner turret: the constructor tests `capabilities & CAPABILITY_SCANNER_TURRET` and that
// enum is 0x3, which shares the basic sensors' bit (--sensors default measures that robot).
// --sensors none: no sensors at all, the controller steering blind (sensors off).
// Each Enki IRSensor casts three rays (IRSensor.h: "three casted rays, separated by 15 degrees"),
// so the ring is 24 rays a robot.
//
// Like epuck_bench, one untimed first step, then STEPS timed steps; robot-steps = N x STEPS. CPU
// time is this thread's (CLOCK_THREAD_CPUTIME_ID) over the timed World::step calls. Prints one
// JSON line.
#include <enki/PhysicalEngine.h>
#include <enki/robots/e-puck/EPuck.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

namespace {

constexpr double kPitch = 20.0, kDt = 0.1, kReach = 12.0, kGain = 1.0;

double thread_cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

std::uint64_t g_collisions = 0;

class Avoider : public Enki::EPuck {
 public:
  Avoider(unsigned capabilities, bool add_ir) : Enki::EPuck(capabilities), sensing_(add_ir || capabilities != 0) {
    sensors_ = {&infraredSensor0, &infraredSensor1, &infraredSensor2, &infraredSensor3,
                &infraredSensor4, &infraredSensor5, &infraredSensor6, &infraredSensor7};
    if (add_ir)
      for (Enki::IRSensor* s : sensors_) addLocalInteraction(s);
  }

  void controlStep(double dt) override {
    // epuck_swarm's rule (controllers/epuck_swarm.cpp): proximity 1 at the sensor, 0 at its range.
    // Enki's angles count counter-clockwise, so the right side's sensors (0..3) are at -16, -45,
    // -90 and -150 degrees, the left side's (4..7) mirror them; 0 and 7 look ahead.
    double left = 0.0, right = 0.0, front = 0.0;
    if (sensing_) {
      for (int k = 0; k < 8; ++k) {
        const double d = sensors_[k]->getDist();
        const double near = d < kReach ? std::clamp(1.0 - d / kReach, 0.0, 1.0) : 0.0;
        if (k <= 2) right = std::max(right, near);
        if (k >= 5) left = std::max(left, near);
        if (k == 0 || k == 7) front = std::max(front, near);
      }
    }
    const double v = 12.8;
    double l = v * (1.0 - kGain * right + kGain * left), r = v * (1.0 - kGain * left + kGain * right);
    if (front > 0.5) {
      l = right > left ? -v : v;
      r = -l;
    }
    leftSpeed = std::clamp(l, -v, v);
    rightSpeed = std::clamp(r, -v, v);
    Enki::EPuck::controlStep(dt);
  }

  void collisionEvent(Enki::PhysicalObject*) override { ++g_collisions; }

 private:
  bool sensing_;
  std::vector<Enki::IRSensor*> sensors_;
};

[[noreturn]] void usage() {
  std::fprintf(stderr, "usage: enki_epuck N STEPS [--sensors ir|none|default]\n");
  std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) usage();
  const int n = std::atoi(argv[1]);
  const long steps = std::atol(argv[2]);
  std::string sensors = "ir";
  for (int k = 3; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--sensors" && k + 1 < argc) sensors = argv[++k];
    else usage();
  }
  if (n <= 0 || steps <= 0 || (sensors != "ir" && sensors != "none" && sensors != "default")) usage();

  const int side = static_cast<int>(std::ceil(std::sqrt(n)));
  const double size = side * kPitch;
  Enki::World world(size, size);
  std::vector<Avoider*> bots;
  for (int k = 0; k < n; ++k) {
    Avoider* b = sensors == "default" ? new Avoider(Enki::EPuck::CAPABILITY_BASIC_SENSORS, false)
                                      : new Avoider(Enki::EPuck::CAPABILITY_NONE, sensors == "ir");
    const double logo_heading = std::fmod(k * 2.399963, 2 * M_PI);  // 0 = +y, clockwise
    b->pos = Enki::Point(kPitch * (k % side + 0.5), kPitch * (k / side + 0.5));
    b->angle = M_PI / 2 - logo_heading;  // Enki: 0 = +x, counter-clockwise
    world.addObject(b);
    bots.push_back(b);
  }

  world.step(kDt, 1);  // untimed, as epuck_bench's start step
  g_collisions = 0;
  // Between the timed steps, how far each robot got (epuck_bench measures the same).
  std::vector<Enki::Point> last;
  for (const Avoider* b : bots) last.push_back(b->pos);
  double cpu = 0.0, wall = 0.0, moved = 0.0;
  for (long s = 0; s < steps; ++s) {
    const auto w0 = std::chrono::steady_clock::now();
    const double c0 = thread_cpu_seconds();
    world.step(kDt, 1);
    cpu += thread_cpu_seconds() - c0;
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    for (std::size_t k = 0; k < bots.size(); ++k) {
      moved += (bots[k]->pos - last[k]).norm();
      last[k] = bots[k]->pos;
    }
  }
  const double robot_steps = static_cast<double>(n) * steps;
  std::printf("{\"bench\":\"enki_epuck\",\"robots\":%d,\"steps\":%ld,\"sensors\":\"%s\",\"rays_per_robot\":%d,"
              "\"cpu_seconds\":%.6g,\"wall_seconds\":%.6g,\"robot_steps_per_cpu_second\":%.6g,"
              "\"cpu_ns_per_robot_step\":%.6g,\"mean_speed\":%.6g,\"collision_events_per_robot_second\":%.6g}\n",
              n, steps, sensors.c_str(), sensors == "none" ? 0 : 24, cpu, wall, robot_steps / cpu, cpu * 1e9 / robot_steps, moved / (robot_steps * kDt),
              g_collisions / (robot_steps * kDt));
  return 0;
}
