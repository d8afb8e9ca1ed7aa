// SPDX-License-Identifier: MIT
// Arcs, drive and wheels in the controller API (Turtle::arc, drive, wheels) and in the script
// controller: laps that close, a touch on an arc at its closed-form time, wheels against the arc
// they imply, the speed limits, mirrors, and the pen's chords.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "fixtures.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/remote.hpp"
#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/world_server.hpp"

using namespace turtlegas;
using namespace turtlegas::turtle;
using turtlegas::test::arena;
using turtlegas::test::body;

namespace {

/// The fixture's arena made 800 wide: room for circles of radius 100 about x = 300.
sim::WorldDef wide() {
  sim::WorldDef d = arena();
  d.arena.width = 800;
  return d;
}

/// A world of one turtle (the fixture's: radius 10, speed 50, turn rate 180 degrees/s) at
/// (200, 200) heading 0, running `program`; gps on.
struct OneTurtle {
  explicit OneTurtle(std::function<void(Turtle&)> program, sim::WorldDef d = wide(), double axle = 0.0,
                     bool builder = false) {
    if (d.turtles.empty()) d.turtles.push_back(body("t", {200, 200}, 0));
    Registry r = base_registry();
    r.add("p", [program](Turtle& t, const Params&) { program(t); });
    TurtleProgram p;
    p.controller = "p";
    p.gps = true;
    p.axle = axle;
    p.builder = builder;
    std::vector<TurtleProgram> programs(d.turtles.size());
    programs[0] = p;
    server = std::make_unique<WorldServer>(d, programs, r);
  }
  WorldServer& operator*() { return *server; }
  WorldServer* operator->() { return server.get(); }
  std::unique_ptr<WorldServer> server;
};

double deg(double rad) { return rad * 180.0 / M_PI; }

/// The pose after driving at v turning at w rad/s (clockwise) for time t from (x0, heading h0):
/// the charged flight's closed form.
sim::Vec2 arc_pos(sim::Vec2 x0, double h0, double v, double w, double t) {
  const sim::Vec2 u{std::sin(h0), std::cos(h0)};
  const sim::Vec2 ju{u.y, -u.x};
  const double phi = w * t;
  return x0 + (v / w) * (std::sin(phi) * u + (1.0 - std::cos(phi)) * ju);
}

}  // namespace

TEST_CASE("a turtle driving full circles with arc returns to its start after 10^4 laps", "[runtime][arc]") {
  for (sim::Mode mode : {sim::Mode::exact, sim::Mode::step}) {
    INFO((mode == sim::Mode::exact ? "exact" : "step"));
    sim::WorldDef d = arena();
    d.dt = 0.5;
    d.turtles.push_back(body("t", {200, 200}, 30));
    static double odometer;
    static int laps;
    laps = 0;
    Registry r = base_registry();
    r.add("p", [](Turtle& t, const Params&) {
      for (int k = 0; k < 10000; ++k) {
        if (t.arc(100, k % 2 == 0 ? 360 : -360).touched()) return;  // right laps and left laps
        ++laps;
      }
      odometer = t.odometer();
    });
    TurtleProgram p;
    p.controller = "p";
    ServerOptions o;
    o.mode = mode;
    WorldServer s(d, {p}, r, o);
    // 50 units/s on a circle of radius 100: a lap takes 4 pi s, and the next starts at a boundary.
    s.run_until(10000 * (4 * M_PI + 0.5) + 10);
    const auto info = s.turtle(0);
    REQUIRE(laps == 10000);
    CHECK(info.finished);
    CHECK(info.fault.empty());
    INFO("drift " << info.state.pos.x - 200 << ", " << info.state.pos.y - 200 << ", heading "
                  << info.state.heading - M_PI / 6);
    CHECK(std::abs(info.state.pos.x - 200) <= 1e-12);
    CHECK(std::abs(info.state.pos.y - 200) <= 1e-12);
    CHECK(std::abs(std::remainder(info.state.heading - M_PI / 6, 2 * M_PI)) <= 1e-12);
    CHECK(odometer == Approx(10000 * 2 * M_PI * 100).epsilon(1e-11));
  }
}

TEST_CASE("an arc stopped by a wall stops dead at the closed-form contact time", "[runtime][arc]") {
  // From (200, 200) heading 0, clockwise on a circle of radius 100 about (300, 200) at 50 units/s
  // (w = 0.5 rad/s): the centre is at y = 200 + 100 sin(phi); a wall at y = 280 is touched by the
  // disc of radius 10 at sin(phi) = 0.7.
  sim::WorldDef d = arena();
  d.walls.push_back({"top", {0, 280}, {400, 280}});
  static Result result;
  static std::vector<Touch> interrupts;
  static double heading, odometer;
  static std::optional<sim::Vec2> pos;
  interrupts.clear();
  OneTurtle s(
      [](Turtle& t) {
        t.on_touch([](const Touch& touch) { interrupts.push_back(touch); });
        result = t.arc(100, 90);
        heading = t.heading();
        odometer = t.odometer();
        pos = t.position();
      },
      d);
  s->run_until(10);
  const double phi = std::asin(0.7);
  REQUIRE(result.touched());
  CHECK(std::abs(result.touch().t - phi / 0.5) <= 1e-9);
  CHECK(result.touch().what == "top");
  CHECK(result.touch().kind == "wall");
  // The contact point is due north (+y), the heading phi east of it: bearing 360 - phi, in front.
  CHECK(result.touch().front());
  CHECK(std::abs(result.touch().bearing - (360.0 - deg(phi))) <= 1e-9);
  REQUIRE(interrupts.size() == 1);
  CHECK(interrupts[0].t == result.touch().t);
  CHECK(std::abs(result.done() - 100 * phi) <= 1e-9);  // the distance along the arc
  CHECK(odometer == result.done());
  CHECK(std::abs(heading - deg(phi)) <= 1e-9);
  REQUIRE(pos);
  CHECK(std::abs(pos->x - (300 - 100 * std::cos(phi))) <= 1e-9);
  CHECK(std::abs(pos->y - (200 + 100 * std::sin(phi))) <= 1e-9);
  CHECK(s->world().measure_overlap().relative <= 1e-9);
}

TEST_CASE("arc: its speed, a turn on the spot, the end pose in closed form, and bad arguments", "[runtime][arc]") {
  // Radius 5: 50 units/s would turn at 10 rad/s, past the turn rate (pi rad/s): the turtle drives
  // at 5 pi units/s instead. A quarter turn then takes 0.5 s.
  static double t_end, heading, done;
  static std::optional<sim::Vec2> pos;
  OneTurtle s([](Turtle& t) {
    done = t.arc(5, -90).done();
    t_end = t.time();
    heading = t.heading();
    pos = t.position();
  });
  s->run_until(2);
  CHECK(t_end == Approx(0.5));  // the command ended at 0.5 s, a control boundary
  CHECK(std::abs(heading - 270.0) <= 1e-12);
  REQUIRE(pos);
  CHECK(std::abs(pos->x - 195) <= 1e-12);
  CHECK(std::abs(pos->y - 205) <= 1e-12);
  CHECK(std::abs(done - 5 * M_PI / 2) <= 1e-12);

  // Radius 0 turns on the spot at the turn rate, as right() does; it drives no distance.
  static Result spin;
  OneTurtle s0([](Turtle& t) {
    spin = t.arc(0, 90);
    heading = t.heading();
    t_end = t.time();
  });
  s0->run_until(2);
  CHECK(spin.done() == 0.0);
  CHECK(std::abs(heading - 90.0) <= 1e-12);
  CHECK(t_end == Approx(0.5));
  CHECK(s0->turtle(0).state.pos == sim::Vec2{200, 200});

  for (const auto& [call, fault] : std::vector<std::pair<std::function<void(Turtle&)>, std::string>>{
           {[](Turtle& t) { t.arc(-5, 90); }, "arc(-5, 90): the radius must be a finite number of units >= 0"},
           {[](Turtle& t) { t.arc(5, NAN); }, "arc(5, nan): the radius"},
           {[](Turtle& t) { t.drive(5, 10, -1); }, "drive(5, 10, -1): the speed"},
           {[](Turtle& t) { t.wheels(INFINITY, 1, 1); }, "wheels(inf, 1, 1): the wheel speeds"},
       }) {
    OneTurtle bad(call);
    bad->run_until(1);
    CAPTURE(fault);
    CHECK(bad->turtle(0).fault.find("turtle 't': " + fault) != std::string::npos);
  }
}

TEST_CASE("wheels(l, r) drives the arc it implies; too fast, both wheels slow by one factor", "[runtime][arc]") {
  // Axle 30, wheels 40 and 20: 30 units/s turning (40 - 20) / 30 rad/s clockwise, a circle of
  // radius axle / 2 * (l + r) / |r - l| = 45. For 3 s: a turn of 2 rad.
  static double heading_w, heading_a, odo_w, odo_a, axle;
  static std::optional<sim::Vec2> pos_w, pos_a;
  OneTurtle w(
      [](Turtle& t) {
        axle = t.axle();
        odo_w = t.wheels(40, 20, 3).done();
        heading_w = t.heading();
        pos_w = t.position();
      },
      arena(), 30.0);
  w->run_until(5);
  OneTurtle a([](Turtle& t) {
    odo_a = t.arc(45, deg(2.0)).done();
    heading_a = t.heading();
    pos_a = t.position();
  });
  a->run_until(5);
  CHECK(axle == 30.0);
  REQUIRE(pos_w);
  REQUIRE(pos_a);
  const sim::Vec2 x = arc_pos({200, 200}, 0, 30, 2.0 / 3.0, 3.0);
  CHECK(std::abs(pos_w->x - x.x) <= 1e-9);
  CHECK(std::abs(pos_w->y - x.y) <= 1e-9);
  CHECK(std::abs(pos_w->x - pos_a->x) <= 1e-9);
  CHECK(std::abs(pos_w->y - pos_a->y) <= 1e-9);
  CHECK(std::abs(heading_w - deg(2.0)) <= 1e-9);
  CHECK(std::abs(heading_w - heading_a) <= 1e-9);
  CHECK(std::abs(odo_w - 90) <= 1e-9);
  CHECK(std::abs(odo_w - odo_a) <= 1e-9);

  // The default axle is twice the radius. Wheels of 100 and 50 on a turtle of speed 50 run at 50
  // and 25 (the same circle, more slowly): the very pose of wheels(50, 25).
  static sim::TurtleState fast, slow;
  OneTurtle f([](Turtle& t) {
    axle = t.axle();
    t.wheels(100, 50, 2);
  });
  f->run_until(3);
  CHECK(axle == 20.0);
  fast = f->turtle(0).state;
  OneTurtle g([](Turtle& t) { t.wheels(50, 25, 2); });
  g->run_until(3);
  slow = g->turtle(0).state;
  CHECK(fast.pos == slow.pos);
  CHECK(fast.heading == slow.heading);
  const sim::Vec2 y = arc_pos({200, 200}, 0, 37.5, 25.0 / 20.0, 2.0);
  CHECK(std::abs(fast.pos.x - y.x) <= 1e-9);
  CHECK(std::abs(fast.pos.y - y.y) <= 1e-9);
}

TEST_CASE("drive: v and omega, scaled down together past the turtle's speed or turn rate", "[runtime][arc]") {
  static sim::TurtleState a, b;
  // 100 units/s and 90 degrees/s on a turtle of speed 50: both halve (a circle of the same radius).
  OneTurtle f([](Turtle& t) { t.drive(100, 90, 2); });
  f->run_until(3);
  OneTurtle g([](Turtle& t) { t.drive(50, 45, 2); });
  g->run_until(3);
  CHECK(f->turtle(0).state.pos == g->turtle(0).state.pos);
  const sim::Vec2 x = arc_pos({200, 200}, 0, 50, M_PI / 4, 2.0);
  CHECK(std::abs(g->turtle(0).state.pos.x - x.x) <= 1e-9);
  CHECK(std::abs(g->turtle(0).state.pos.y - x.y) <= 1e-9);
  // No speed and no turn: it stands still for its time, driving nothing.
  static double t_end;
  static Result still;
  OneTurtle z([](Turtle& t) {
    still = t.drive(0, 0, 2);
    t_end = t.time();
  });
  z->run_until(5);
  CHECK(t_end == Approx(2.0));
  CHECK(still.done() == 0.0);
  CHECK(z->turtle(0).state.pos == sim::Vec2{200, 200});
  // 10 units/s and 360 degrees/s on a turn rate of 180: both halve. Backwards and to the left.
  OneTurtle h([](Turtle& t) { t.drive(-10, -360, 1); });
  h->run_until(2);
  OneTurtle k([](Turtle& t) { t.drive(-5, -180, 1); });
  k->run_until(2);
  CHECK(std::abs(h->turtle(0).state.pos.x - k->turtle(0).state.pos.x) <= 1e-12);
  CHECK(std::abs(h->turtle(0).state.pos.y - k->turtle(0).state.pos.y) <= 1e-12);
  const sim::Vec2 y = arc_pos({200, 200}, 0, -5, -M_PI, 1.0);
  CHECK(std::abs(k->turtle(0).state.pos.x - y.x) <= 1e-9);
  CHECK(std::abs(k->turtle(0).state.pos.y - y.y) <= 1e-9);
  CHECK(std::abs(std::remainder(k->turtle(0).state.heading + M_PI, 2 * M_PI)) <= 1e-12);
}

TEST_CASE("through a mirror an arc turns the other way and the wheels exchange", "[runtime][arc][mirror]") {
  // The mirror line is x = 200 through the start: the mirrored run is the plain one reflected.
  std::vector<std::function<void(Turtle&)>> programs = {
      [](Turtle& t) { t.arc(60, 135); t.drive(20, -40, 2); t.wheels(30, 10, 1.5); },
      [](Turtle& t) {
        Turtle m = t.mirrored(0, sim::Vec2{200, 0});
        m.arc(60, 135);
        m.drive(20, -40, 2);
        m.wheels(30, 10, 1.5);
      }};
  static double seen_heading;
  std::vector<sim::TurtleState> end;
  for (const auto& p : programs) {
    OneTurtle s(p);
    s->run_until(20);
    CHECK(s->turtle(0).finished);
    CHECK(s->turtle(0).fault.empty());
    end.push_back(s->turtle(0).state);
  }
  INFO("plain " << end[0].pos.x << ", " << end[0].pos.y << "; mirrored " << end[1].pos.x << ", " << end[1].pos.y);
  CHECK(end[0].pos.x != Approx(200).margin(1));  // it went somewhere off the line
  CHECK(std::abs(400 - end[1].pos.x - end[0].pos.x) <= 1e-9);
  CHECK(std::abs(end[1].pos.y - end[0].pos.y) <= 1e-9);
  CHECK(std::abs(std::remainder(end[1].heading + end[0].heading, 2 * M_PI)) <= 1e-12);
  // What the mirrored program sees is the plain program's view.
  OneTurtle s([](Turtle& t) {
    Turtle m = t.mirrored();
    m.arc(60, 45);
    seen_heading = m.heading();
  });
  s->run_until(5);
  CHECK(std::abs(seen_heading - 45) <= 1e-12);
  CHECK(std::abs(deg(s->turtle(0).state.heading) + 45) <= 1e-12);
}

TEST_CASE("a pen on an arc lays chords: within radius / 20 of it, at most 45 degrees each", "[runtime][arc][pen]") {
  // Radius 100 and a turtle of radius 10: the sagitta bound 0.5 gives chords of 2 acos(0.995)
  // = 0.2 rad; half a lap takes 16 of them.
  OneTurtle s([](Turtle& t) {
    t.pen_down();
    t.arc(100, 180);
    t.pen_up();
  });
  s->run_until(10);
  const auto trail = s->turtle(0).trail;
  REQUIRE(trail.size() == 17);
  CHECK(trail.front() == sim::Vec2{200, 200});
  CHECK(trail.back() == s->turtle(0).state.pos);
  CHECK(std::abs(trail.back().x - 400) <= 1e-9);
  const sim::Vec2 c{300, 200};
  for (std::size_t k = 0; k + 1 < trail.size(); ++k) {
    CHECK(std::abs(norm(trail[k] - c) - 100) <= 1e-9);
    const double chord = norm(trail[k + 1] - trail[k]);
    const double sagitta = 100 - std::sqrt(100 * 100 - chord * chord / 4);
    CHECK(sagitta <= 0.5 + 1e-9);
    CHECK(sagitta >= 0.4);  // equal chords, as long as the bound allows
  }
}

TEST_CASE("a wall pen on an arc lays the chords of one lap, closed; others collide with them", "[runtime][arc][pen]") {
  // 400 degrees about (300, 200), radius 100: the circle once, with no wall laid twice.
  sim::WorldDef d = wide();
  d.turtles.push_back(body("t", {200, 200}, 0));
  d.turtles.push_back(body("inside", {300, 200}, 0, 30));
  Registry r = base_registry();
  r.add("p", [](Turtle& t, const Params&) {
    t.pen_down(PenMode::wall);
    t.arc(100, 400);
  });
  r.add("out", [](Turtle& t, const Params&) {
    t.wait(20);
    t.forward(200);  // stopped by the circle of walls at y = 290
  });
  TurtleProgram p, q;
  p.controller = "p";
  p.builder = true;
  q.controller = "out";
  WorldServer s(d, {p, q}, r);
  std::vector<LogEvent> log;
  s.set_event_log(&log);
  s.run_until(30);
  std::vector<sim::WallDef> walls;
  for (const auto& w : s.world().walls())
    if (w.id.rfind("t-w", 0) == 0) walls.push_back(w);
  // n = ceil(400 degrees / 0.2 rad) = 35 chords of 400/35 degrees; 31 of them end within the first
  // lap, and one more closes it back to the start.
  CHECK(walls.size() == 32);
  const sim::Vec2 c{300, 200};
  for (const auto& w : walls) {
    CHECK(std::abs(norm(w.from - c) - 100) <= 1e-9);
    CHECK(std::abs(norm(w.to - c) - 100) <= 1e-9);
  }
  // Every point of the circle lies within the sagitta bound of a wall.
  double worst = 0.0;
  for (int k = 0; k < 3600; ++k) {
    const double a = 2 * M_PI * k / 3600;
    const sim::Vec2 p{c.x + 100 * std::cos(a), c.y + 100 * std::sin(a)};
    double best = 1e300;
    for (const auto& w : walls) {
      const sim::Vec2 u = w.to - w.from;
      const double f = std::clamp(dot(p - w.from, u) / dot(u, u), 0.0, 1.0);
      best = std::min(best, norm(p - (w.from + f * u)));
    }
    worst = std::max(worst, best);
  }
  INFO("farthest point of the circle from the walls: " << worst);
  CHECK(worst <= 0.5 + 1e-9);
  for (const auto& e : log) CHECK(e.kind != "wall-refused");
  // The turtle inside drove up into the chord above it, within the sagitta of the circle.
  CHECK(s.turtle(1).state.pos.y <= 290 + 1e-9);
  CHECK(s.turtle(1).state.pos.y >= 290 - 0.5 - 1e-9);
  bool hit = false;
  for (const auto& e : log) hit = hit || (e.kind == "turtle-wall" && e.a == "inside" && e.b.rfind("t-w", 0) == 0);
  CHECK(hit);
}

TEST_CASE("an arc of exactly one lap ends where it began, and its pens draw and lay the whole circle", "[runtime][arc][pen]") {
  // The closed form brings a 360-degree arc back to its start exactly: the pens must not take
  // that for a stroke of no length (before, a lap laid no wall and drew no line).
  OneTurtle line([](Turtle& t) {
    t.pen_down();
    t.arc(100, 360);
  });
  line->run_until(30);
  const auto trail = line->turtle(0).trail;
  REQUIRE(line->turtle(0).state.pos == sim::Vec2{200, 200});
  // The start, then 32 chords of 0.2 rad (one more vertex when the lap's turn comes out past 2 pi
  // by round-off: the rest of the turn past the lap, a chord of almost no length).
  REQUIRE(trail.size() >= 33);
  REQUIRE(trail.size() <= 34);
  CHECK(trail.back() == sim::Vec2{200, 200});
  for (const auto& v : trail) CHECK(std::abs(norm(v - sim::Vec2{300, 200}) - 100) <= 1e-9);
  for (std::size_t k = 0; k + 1 < trail.size(); ++k) CHECK(norm(trail[k + 1] - trail[k]) <= 2 * 100 * std::sin(0.1) + 1e-9);

  sim::WorldDef d = wide();
  d.turtles.push_back(body("t", {200, 200}, 0));
  Registry r = base_registry();
  r.add("p", [](Turtle& t, const Params&) {
    t.pen_down(PenMode::wall);
    t.arc(100, 360);
  });
  TurtleProgram p;
  p.controller = "p";
  p.builder = true;
  WorldServer s(d, {p}, r);
  s.run_until(30);
  std::size_t laid = 0;
  for (const auto& w : s.world().walls())
    if (w.id.rfind("t-w", 0) == 0) {
      ++laid;
      CHECK(std::abs(norm(w.from - sim::Vec2{300, 200}) - 100) <= 1e-9);
      CHECK(std::abs(norm(w.to - sim::Vec2{300, 200}) - 100) <= 1e-9);
    }
  CHECK(laid == 32);
}

TEST_CASE("the script controller drives arcs, drive and wheels", "[runtime][arc]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("t", {200, 200}, 0));
  TurtleProgram p;
  p.params = nlohmann::json::parse(R"({"commands": [["arc", 100, 90], ["drive", 20, -30, 3], ["wheels", 10, 30, 2]]})");
  p.axle = 40;
  WorldServer s(d, {p}, base_registry());
  s.run_until(20);
  CHECK(s.turtle(0).fault.empty());
  CHECK(s.turtle(0).finished);
  // The same three by hand.
  sim::Vec2 x = arc_pos({200, 200}, 0, 50, 0.5, M_PI);  // (300, 300), heading 90
  double h = M_PI / 2;
  x = arc_pos(x, h, 20, -M_PI / 6, 3);
  h -= M_PI / 2;
  x = arc_pos(x, h, 20, -0.5, 2);
  h -= 1.0;
  CHECK(std::abs(s.turtle(0).state.pos.x - x.x) <= 1e-9);
  CHECK(std::abs(s.turtle(0).state.pos.y - x.y) <= 1e-9);
  CHECK(std::abs(std::remainder(s.turtle(0).state.heading - h, 2 * M_PI)) <= 1e-12);

  for (const auto& [params, fault] : std::vector<std::pair<const char*, const char*>>{
           {R"({"commands": [["arc", 100]]})", "params.commands[0]: 'arc' needs 2 numbers, e.g. [\"arc\", 50, 90]"},
           {R"({"commands": [["wheels", 1, 2, "x"]]})", "params.commands[0]: 'wheels' needs 3 numbers, e.g. [\"wheels\", 20, 10, 2]"},
       }) {
    TurtleProgram bad;
    bad.params = nlohmann::json::parse(params);
    sim::WorldDef e = arena();
    e.turtles.push_back(body("t", {200, 200}, 0));
    WorldServer b(e, {bad}, base_registry());
    b.run_until(1);
    CHECK(b.turtle(0).fault == std::string("its program threw: ") + fault);
  }
}

TEST_CASE("a remote turtle's arc, drive and wheels run as the C++ program's", "[runtime][arc][remote]") {
  using K = RemoteCommand::Kind;
  std::vector<RemoteCommand> commands(3);
  commands[0].kind = K::arc;
  commands[0].steer = {70, -120, 0};
  commands[1].kind = K::drive;
  commands[1].steer = {-25, 60, 1.5};
  commands[2].kind = K::wheels;
  commands[2].steer = {12, 30, 2};
  struct Source : InputSource {
    std::vector<RemoteCommand> commands;
    std::size_t next_one = 0;
    std::optional<RemoteCommand> next(std::uint64_t, std::size_t) override {
      if (next_one == commands.size()) return std::nullopt;
      return commands[next_one++];
    }
  };
  auto source = std::make_shared<Source>();
  source->commands = commands;
  std::vector<double> done;
  ServerOptions o;
  o.input = source;
  o.remote_reports = [&](const RemoteReport& r) {
    if (r.kind == RemoteReport::Kind::result) done.push_back(r.result.done());
  };
  sim::WorldDef d = wide();
  d.turtles.push_back(body("t", {200, 200}, 0));
  TurtleProgram remote;
  remote.controller = "remote";
  WorldServer s(d, {remote}, base_registry(), o);
  s.run_until(20);
  static std::vector<double> cpp_done;
  cpp_done.clear();
  OneTurtle c([](Turtle& t) {
    cpp_done.push_back(t.arc(70, -120).done());
    cpp_done.push_back(t.drive(-25, 60, 1.5).done());
    cpp_done.push_back(t.wheels(12, 30, 2).done());
  });
  c->run_until(20);
  CHECK(done == cpp_done);
  CHECK(done.size() == 3);
  CHECK(s.turtle(0).state.pos == c->turtle(0).state.pos);
  CHECK(s.turtle(0).state.heading == c->turtle(0).state.heading);
}

TEST_CASE("an arc where a wall turns is a fault of that turtle, and the world runs on", "[runtime][arc][isolation]") {
  sim::WorldDef d = wide();
  sim::WallDef arm{"arm", {600, 300}, {700, 300}};
  arm.keys.push_back({10.0, {600, 300}, {600, 380}});  // turns about its first end
  d.walls.push_back(arm);
  d.turtles.push_back(body("t", {200, 200}, 0));
  d.turtles.push_back(body("u", {100, 100}, 90));
  TurtleProgram arcs, straight;
  arcs.params = nlohmann::json::parse(R"({"commands": [["forward", 10], ["arc", 50, 90], ["forward", 10]]})");
  straight.params = nlohmann::json::parse(R"({"commands": [["forward", 100]]})");
  WorldServer s(d, {arcs, straight}, base_registry());
  s.run_until(5);
  CHECK(s.turtle(0).finished);
  CHECK(s.turtle(0).fault.find("its arc was refused: ") == 0);
  CHECK(s.turtle(0).fault.find("arcs are not simulated while a wall turns or stretches") != std::string::npos);
  CHECK(s.turtle(0).state.pos == sim::Vec2{200, 210});  // it stopped where the refused arc began
  CHECK(s.turtle(1).fault.empty());
  CHECK(std::abs(s.turtle(1).state.pos.x - 200) <= 1e-9);
}
