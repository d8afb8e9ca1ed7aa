// SPDX-License-Identifier: MIT
// The 3-D gas's loop (docs/architecture.md, "The 3-D room"). The order of work of one event:
//   1. pop the body i with the earliest pending event (key, then id: ties are deterministic);
//   2. a sphere partner whose course-change count moved since the prediction: stale, predict i
//      afresh from now;
//   3. a collision: move both to the contact time, reflect the relative velocity about the line
//      of centres (the memo's vector form), raise both counts, predict both afresh;
//   4. a wall feature: reflect about the face normal, or from the edge's nearest point, or from
//      the corner; raise the count; predict afresh;
//   5. a cell crossing: the body enters the next cell (wrapped in a periodic arena, removed with
//      `exit` from an open one) and is predicted afresh; its count does not move (same flight).
// A prediction looks at the 27 cells around the body's cell (with their periodic shifts) and at
// the walls listed in its own cell, up to the earliest candidate found so far.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "engine3d/polygon3.hpp"
#include "engine3d/overlap3.hpp"
#include "event_queue.hpp"
#include "turtlegas/sim/roots.hpp"
#include "turtlegas/sim/toi3.hpp"
#include "turtlegas/sim/world3d.hpp"

namespace turtlegas::sim {
namespace {

using detail::EventQueue;
using detail::Polygon3;

enum class Pending : std::uint8_t { none, cell, pair, face, edge, corner };

struct Record {
  EventQueue::Node node;
  Vec3 x, v, a;            // at local time t
  double t = 0.0;
  double r = 1.0, m = 1.0;
  std::uint32_t count = 0;  // course changes
  std::uint32_t cell = 0;
  std::uint32_t next = EventQueue::kAbsent, prev = EventQueue::kAbsent;  // cell list
  // The pending event.
  Pending kind = Pending::none;
  std::uint8_t axis = 0;
  std::int8_t dir = 0;
  bool alive = true;
  std::uint32_t partner = 0;      // sphere or wall
  std::uint32_t partner_count = 0;  // or the feature index
  double cand_t = kNever;  // the pending contact's time (absolute)
  double exit_t = kNever;  // the cell exit's time (absolute)
};

constexpr std::uint32_t kNone = EventQueue::kAbsent;

/// 2-D's departure floor (contacts.hpp): an inelastic response leaves at 2^-40 of the speeds at
/// least, far below any physics and far above the round-off of its products.
constexpr double kDepartFloor = 0x1p-40;

}  // namespace

double distance_to_polygon(const Vec3& x, const std::vector<Vec3>& corners) {
  return Polygon3(corners).distance(x);
}

namespace {

/// The first pair of spheres that overlap (beyond round-off), in words; empty when none do. A hash
/// grid of cells one largest diameter wide: O(N) for a gas, not O(N^2).
std::string first_sphere_overlap(const World3Def& def) {
  double rmax = 0.0;
  for (const Sphere3Def& s : def.spheres) rmax = std::max(rmax, s.radius);
  if (def.spheres.size() < 2) return {};
  const double side = 2.0 * rmax;
  std::array<std::int64_t, 3> cells{};
  for (int a = 0; a < 3; ++a) cells[a] = std::max<std::int64_t>(1, static_cast<std::int64_t>(def.size[a] / side));
  const bool periodic = def.boundary == Boundary3::periodic;
  auto cell_of = [&](const Vec3& p) {
    std::array<std::int64_t, 3> c{};
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp<std::int64_t>(static_cast<std::int64_t>(p[a] / def.size[a] * static_cast<double>(cells[a])), 0,
                                      cells[a] - 1);
    return c;
  };
  auto key = [&](std::array<std::int64_t, 3> c) { return (c[0] * cells[1] + c[1]) * cells[2] + c[2]; };
  std::unordered_map<std::int64_t, std::vector<std::size_t>> grid;
  for (std::size_t i = 0; i < def.spheres.size(); ++i) grid[key(cell_of(def.spheres[i].pos))].push_back(i);
  for (std::size_t i = 0; i < def.spheres.size(); ++i) {
    const std::array<std::int64_t, 3> c = cell_of(def.spheres[i].pos);
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          std::array<std::int64_t, 3> o{c[0] + dx, c[1] + dy, c[2] + dz};
          bool outside = false;
          for (int a = 0; a < 3; ++a) {
            if (o[a] >= 0 && o[a] < cells[a]) continue;
            if (periodic) o[a] = (o[a] + cells[a]) % cells[a];
            else outside = true;
          }
          if (outside) continue;
          const auto it = grid.find(key(o));
          if (it == grid.end()) continue;
          for (std::size_t j : it->second) {
            if (j <= i) continue;
            Vec3 d = def.spheres[j].pos - def.spheres[i].pos;
            if (periodic)
              for (int a = 0; a < 3; ++a) d[a] -= def.size[a] * std::nearbyint(d[a] / def.size[a]);
            const double reach = def.spheres[i].radius + def.spheres[j].radius;
            if (norm(d) < reach * (1.0 - 1e-12))
              return "sphere " + std::to_string(i) + " and sphere " + std::to_string(j) + " overlap (centres " +
                     std::to_string(norm(d)) + " apart, radii sum " + std::to_string(reach) +
                     "): move one, or make them smaller";
          }
        }
  }
  return {};
}

}  // namespace

std::string check_world3(const World3Def& def) {
  for (int a = 0; a < 3; ++a)
    if (!(def.size[a] > 0.0) || !std::isfinite(def.size[a])) return "the arena's width, height and depth must be finite and > 0";
  if (!is_finite(def.gravity) || !is_finite(def.electric) || !is_finite(def.magnetic))
    return "gravity, electric and magnetic must be finite";
  if (def.mode == Mode::step && !(def.magnetic == Vec3{}))
    return "a magnetic field is simulated in exact mode only in 3-D (step mode's kicks do not turn velocities yet)";
  if (!(def.tc >= 0.0) || !std::isfinite(def.tc)) return "tc must be finite and >= 0";
  if (def.mode == Mode::step && !(def.dt > 0.0 && std::isfinite(def.dt))) return "step mode's dt must be finite and > 0";
  for (std::size_t i = 0; i < def.spheres.size(); ++i) {
    const Sphere3Def& s = def.spheres[i];
    const std::string at = "sphere " + std::to_string(i) + ": ";
    if (!(s.radius > 0.0) || !std::isfinite(s.radius)) return at + "radius must be finite and > 0";
    if (!(s.mass > 0.0) || !std::isfinite(s.mass)) return at + "mass must be finite and > 0";
    if (!is_finite(s.pos) || !is_finite(s.vel) || !std::isfinite(s.charge)) return at + "pos, vel and charge must be finite";
    if (!(s.restitution >= 0.0 && s.restitution <= 1.0))
      return at + "restitution must be in [0, 1]; 1 is elastic, 0 perfectly inelastic";
    for (int a = 0; a < 3; ++a)
      if (s.pos[a] < 0.0 || s.pos[a] >= def.size[a]) return at + "pos must lie in the arena [0, size)";
    if (def.boundary == Boundary3::walls)
      for (int a = 0; a < 3; ++a)
        if (s.pos[a] < s.radius * (1.0 - 1e-12) || s.pos[a] > def.size[a] - s.radius * (1.0 - 1e-12))
          return at + "overlaps the arena's walls (its centre must be at least its radius inside each face)";
  }
  for (std::size_t w = 0; w < def.walls.size(); ++w) {
    const auto& c = def.walls[w].corners;
    const std::string at = "wall " + std::to_string(w) + ": ";
    if (c.size() < 3) return at + "needs 3 or more corners";
    if (!(def.walls[w].restitution >= 0.0 && def.walls[w].restitution <= 1.0))
      return at + "restitution must be in [0, 1]; 1 is elastic, 0 perfectly inelastic";
    for (const Vec3& p : c) {
      if (!is_finite(p)) return at + "corners must be finite";
      for (int a = 0; a < 3; ++a)
        if (p[a] < 0.0 || p[a] > def.size[a]) return at + "corners must lie in the arena";
    }
    Vec3 area;
    for (std::size_t k = 0; k < c.size(); ++k) area += cross(c[k], c[(k + 1) % c.size()]);
    const double an = norm(area);
    double scale = 0.0;
    for (std::size_t k = 0; k < c.size(); ++k) scale = std::max(scale, norm(c[(k + 1) % c.size()] - c[k]));
    if (!(an > 1e-12 * scale * scale)) return at + "corners are collinear, or not in order around the polygon (no plane)";
    const auto& keys = def.walls[w].keys;
    if (!keys.empty() && def.boundary == Boundary3::periodic)
      return at + "moving walls are not supported in a periodic arena (use \"boundary\": \"walls\" or \"none\")";
    for (std::size_t k = 0; k < keys.size(); ++k) {
      const std::string key = at + "key " + std::to_string(k) + ": ";
      if (!std::isfinite(keys[k].t) || !(keys[k].t > (k == 0 ? 0.0 : keys[k - 1].t)))
        return key + "times must be finite, > 0 and increasing";
      if (!is_finite(keys[k].shift)) return key + "the pose must be finite";
      for (const Vec3& p : c)
        for (int a = 0; a < 3; ++a)
          if (p[a] + keys[k].shift[a] < 0.0 || p[a] + keys[k].shift[a] > def.size[a])
            return key + "the wall leaves the arena (every pose's corners must lie in it)";
    }
    const Vec3 n = (1.0 / an) * area;
    for (std::size_t k = 0; k < c.size(); ++k) {
      if (std::abs(dot(c[k] - c[0], n)) > 1e-9 * scale) return at + "corners are not in one plane";
      const Vec3 e1 = c[(k + 1) % c.size()] - c[k], e2 = c[(k + 2) % c.size()] - c[(k + 1) % c.size()];
      if (!(norm(e1) > 0.0)) return at + "two consecutive corners are the same point";
      if (dot(cross(e1, e2), n) < -1e-12 * scale * scale) return at + "the polygon is not convex (list its corners in order around it)";
    }
  }
  for (std::size_t w = 0; w < def.walls.size(); ++w)
    for (std::size_t i = 0; i < def.spheres.size(); ++i) {
      const Sphere3Def& s = def.spheres[i];
      const double d = distance_to_polygon(s.pos, def.walls[w].corners);
      if (d < s.radius * (1.0 - 1e-12))
        return "sphere " + std::to_string(i) + " overlaps wall " + std::to_string(w) + " (its centre is " +
               std::to_string(d) + " from it, radius " + std::to_string(s.radius) + "): move one of them";
    }
  return first_sphere_overlap(def);
}

struct World3::Impl {
  Boundary3 boundary;
  Vec3 size;
  int n[3] = {1, 1, 1};
  Vec3 w;  // cell sides
  std::vector<Record> rec;
  std::vector<std::uint32_t> head;  // per cell
  std::vector<std::vector<std::uint32_t>> cell_walls;
  std::vector<Polygon3> walls;
  EventQueue queue;
  double now = 0.0;
  std::uint64_t collisions = 0, events = 0;
  double contact_error = 0.0;
  double virial = 0.0;
  std::vector<double> wall_push;  // per wall: sum of m Δv . n over its contacts (World3::wall_push)
  // Moving walls (docs/physics.md, "3-D: moving walls"): per wall, its translation `shift_ref`
  // at time `key_t` and its velocity since, with the keys still ahead. A standing wall has all
  // zero and no keys, and its formulas below are bit for bit those without motion (x - 0 == x).
  struct Motion {
    Vec3 shift_ref, u;
    double t_ref = 0.0;
    std::vector<Wall3Key> keys;
    std::size_t next = 0;  // the key it is heading for (keys.size(): it has stopped)
    Vec3 shift_at(double t) const { return shift_ref + (t - t_ref) * u; }
  };
  std::vector<Motion> motion;  // per wall; empty when no wall moves
  double next_key = kNever;    // the earliest key ahead of any wall
  double wall_work = 0.0;      // World3::wall_work
  // A magnetic field (docs/physics.md, "3-D: magnetic fields"): per sphere omega = (q/m) B, kept
  // only when B != 0. A sphere with omega != 0 flies a helix and every contact of it is found by
  // conservative advancement (first_touch), up to a horizon of at most `cap` (one turn of the
  // fastest-turning sphere): at the horizon it predicts again. In such a scene every crossing
  // predicts in full (pairs are searched only up to each sphere's horizon).
  std::vector<Vec3> omega;
  double cap = kNever;
  double limit = kNever;  // during a prediction: how far every search so far is proven
  // A contact is found within 1e-12 r plus this: 2^-44 of the arena, some 500 times the round-off
  // of a helix's position anywhere in it, so first_touch's margin (half the tolerance) holds.
  double round_off = 0.0;
  bool gyrates(std::uint32_t i) const { return !omega.empty() && !(omega[i] == Vec3{}); }
  Vec3 pos_at(const Record& b, double dt) const {
    const std::uint32_t i = index_of(b);
    return gyrates(i) ? b.x + Helix3(b.v, b.a, omega[i]).displacement(dt) : fly(b.x, b.v, b.a, dt);
  }
  Vec3 vel_at(const Record& b, double dt) const {
    const std::uint32_t i = index_of(b);
    return gyrates(i) ? Helix3(b.v, b.a, omega[i]).velocity(dt) : b.v + dt * b.a;
  }
  std::uint32_t index_of(const Record& b) const { return static_cast<std::uint32_t>(&b - rec.data()); }
  // A sphere's flight as seen by a search: position and velocity at s after `now`, and |x''|.
  struct Path {
    Vec3 x, v, a;
    std::optional<Helix3> helix;
    Vec3 pos(double s) const { return helix ? x + helix->displacement(s) : fly(x, v, a, s); }
    Vec3 vel(double s) const { return helix ? helix->velocity(s) : v + s * a; }
    double accel() const { return helix ? helix->accel() : norm(a); }
  };
  Path path_of(std::uint32_t i) const {
    const Record& b = rec[i];
    Path p{pos_at(b, now - b.t), vel_at(b, now - b.t), b.a, std::nullopt};
    if (gyrates(i)) p.helix.emplace(p.v, b.a, omega[i]);
    return p;
  }
  static constexpr int kMaxSteps = 20000;
  // Conservative advancement (first_touch) with the prediction's running limit.
  template <class Eval>
  double touch(Eval eval, double accel, double horizon, double tol) {
    horizon = std::min(horizon, limit);
    if (!(horizon > 0.0)) return kNever;
    double reached = 0.0;
    const double t = first_touch(eval, accel, horizon, tol, kMaxSteps, reached);
    if (t == kNever && reached < horizon) limit = reached;  // stopped early: predict again there
    return t;
  }
  std::vector<Event3>* log = nullptr;
  // Restitution (docs/physics.md, "3-D: restitution"): kept beside the records, and only when
  // some e < 1, so that an elastic gas's record and loop are unchanged.
  bool inelastic = false;
  double tc = 0.0;
  std::vector<double> e_sphere, e_wall, last_change;
  // Step mode with a field (World3Def::mode): the spheres fly straight (their records' a = 0) and
  // take field_a dt at the end of each step; `steps` steps have ended. Empty in exact mode and
  // without a field, where the two modes are one.
  std::vector<Vec3> field_a;
  double dt = 0.0;
  std::uint64_t steps = 0;
  // The wedge rule's figures (World3::wedged, energy_wedged).
  std::uint64_t wedged = 0;
  double energy_wedged = 0.0;
  // Stops (World3::set_event_limit, set_stop_poll): looked at when `events` reaches next_check.
  std::uint64_t event_limit = ~std::uint64_t{0};
  std::function<bool()> stop_poll;
  std::uint64_t poll_every = 4096;
  std::uint64_t next_check = ~std::uint64_t{0};
  void arm_check() { next_check = stop_poll ? std::min(event_limit, events + poll_every) : event_limit; }
  [[gnu::cold]] void check_stop() {
    if (events >= event_limit)
      throw EventLimitReached("the event limit (" + std::to_string(event_limit) + ") was reached at t = " + std::to_string(now));
    if (stop_poll && stop_poll()) throw StopRequested("stopped at t = " + std::to_string(now));
    arm_check();
  }

  std::uint32_t cell_index(int cx, int cy, int cz) const {
    return static_cast<std::uint32_t>((cz * n[1] + cy) * n[0] + cx);
  }
  void coords(std::uint32_t c, int* k) const {
    k[0] = static_cast<int>(c % n[0]);
    k[1] = static_cast<int>((c / n[0]) % n[1]);
    k[2] = static_cast<int>(c / (static_cast<std::uint32_t>(n[0]) * n[1]));
  }
  void link(std::uint32_t i, std::uint32_t c) {
    Record& b = rec[i];
    b.cell = c;
    b.prev = kNone;
    b.next = head[c];
    if (head[c] != kNone) rec[head[c]].prev = i;
    head[c] = i;
  }
  void unlink(std::uint32_t i) {
    Record& b = rec[i];
    if (b.prev != kNone) rec[b.prev].next = b.next; else head[b.cell] = b.next;
    if (b.next != kNone) rec[b.next].prev = b.prev;
  }
  void bring(Record& b, double t) {
    const double dt = t - b.t;
    if (dt == 0.0) return;
    if (gyrates(index_of(b))) {
      const Vec3 x = pos_at(b, dt);
      b.v = vel_at(b, dt);
      b.x = x;
    } else {
      b.x = fly(b.x, b.v, b.a, dt);
      b.v += dt * b.a;
    }
    b.t = t;
  }

  explicit Impl(const World3Def& def) : boundary(def.boundary), size(def.size) {
    double r_max = 0.0;
    for (const auto& s : def.spheres) r_max = std::max(r_max, s.radius);
    // Without spheres (a world of walls only) one cell per axis.
    const double cell = def.cell > 0.0 ? def.cell : r_max > 0.0 ? 2.0 * r_max * (1.0 + 0x1p-20) : std::max({size.x, size.y, size.z});
    for (int a = 0; a < 3; ++a) {
      n[a] = std::max(1, static_cast<int>(std::min(1024.0, std::floor(size[a] / std::max(cell, 1e-300)))));
      if (boundary == Boundary3::periodic && n[a] < 3)
        throw std::invalid_argument("a periodic arena needs at least 3 cells of the largest diameter on every axis");
      w[a] = size[a] / n[a];
    }
    for (const auto& wd : def.walls) walls.emplace_back(wd.corners);
    for (const auto& s : def.spheres) inelastic = inelastic || s.restitution < 1.0;
    for (const auto& wd : def.walls) inelastic = inelastic || wd.restitution < 1.0;
    if (inelastic) {
      tc = def.tc;
      for (const auto& s : def.spheres) e_sphere.push_back(s.restitution);
      for (const auto& wd : def.walls) e_wall.push_back(wd.restitution);
      e_wall.resize(def.walls.size() + (boundary == Boundary3::walls ? 6 : 0), 1.0);  // the arena's: elastic
      last_change.assign(def.spheres.size(), -kNever);
    }
    if (boundary == Boundary3::walls) {
      const double X = size.x, Y = size.y, Z = size.z;
      walls.emplace_back(std::vector<Vec3>{{0, 0, 0}, {0, Y, 0}, {0, Y, Z}, {0, 0, Z}});
      walls.emplace_back(std::vector<Vec3>{{X, 0, 0}, {X, 0, Z}, {X, Y, Z}, {X, Y, 0}});
      walls.emplace_back(std::vector<Vec3>{{0, 0, 0}, {0, 0, Z}, {X, 0, Z}, {X, 0, 0}});
      walls.emplace_back(std::vector<Vec3>{{0, Y, 0}, {X, Y, 0}, {X, Y, Z}, {0, Y, Z}});
      walls.emplace_back(std::vector<Vec3>{{0, 0, 0}, {X, 0, 0}, {X, Y, 0}, {0, Y, 0}});
      walls.emplace_back(std::vector<Vec3>{{0, 0, Z}, {0, Y, Z}, {X, Y, Z}, {X, 0, Z}});
    }
    wall_push.assign(walls.size(), 0.0);
    bool any_moves = false;
    for (const auto& wd : def.walls) any_moves = any_moves || !wd.keys.empty();
    if (any_moves) {
      motion.resize(walls.size());
      for (std::size_t k = 0; k < def.walls.size(); ++k) {
        motion[k].keys = def.walls[k].keys;
        aim(motion[k]);
      }
      next_key = earliest_key();
    }
    const std::size_t cells = static_cast<std::size_t>(n[0]) * n[1] * n[2];
    head.assign(cells, kNone);
    cell_walls.assign(cells, {});
    // A wall is listed in every cell within r_max of its bounding box: a sphere whose centre
    // is in the cell can touch it only then. A moving wall's box is the one around all its
    // poses: it translates in straight lines between them, so it never leaves that box.
    for (std::uint32_t k = 0; k < walls.size(); ++k) {
      Vec3 box_lo = walls[k].lo, box_hi = walls[k].hi;
      if (k < def.walls.size())
        for (const Wall3Key& key : def.walls[k].keys)
          for (int a = 0; a < 3; ++a) {
            box_lo[a] = std::min(box_lo[a], walls[k].lo[a] + key.shift[a]);
            box_hi[a] = std::max(box_hi[a], walls[k].hi[a] + key.shift[a]);
          }
      int lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::clamp(static_cast<int>(std::floor((box_lo[a] - r_max) / w[a])), 0, n[a] - 1);
        hi[a] = std::clamp(static_cast<int>(std::floor((box_hi[a] + r_max) / w[a])), 0, n[a] - 1);
      }
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x) cell_walls[cell_index(x, y, z)].push_back(k);
    }
    rec.resize(def.spheres.size());
    for (std::uint32_t i = 0; i < rec.size(); ++i) {
      const Sphere3Def& s = def.spheres[i];
      Record& b = rec[i];
      b.x = s.pos;
      b.v = s.vel;
      b.a = def.gravity + (s.charge / s.mass) * def.electric;
      if (def.mode == Mode::step && (b.a.x != 0.0 || b.a.y != 0.0 || b.a.z != 0.0)) {
        field_a.resize(def.spheres.size());
        field_a[i] = b.a;
      }
      b.r = s.radius;
      b.m = s.mass;
      int k[3];
      for (int a = 0; a < 3; ++a) k[a] = std::clamp(static_cast<int>(std::floor(s.pos[a] / w[a])), 0, n[a] - 1);
      link(i, cell_index(k[0], k[1], k[2]));
    }
    if (!field_a.empty()) {
      dt = def.dt;
      for (Record& b : rec) b.a = {};
    }
    if (!(def.magnetic == Vec3{})) {
      omega.resize(def.spheres.size());
      double w_max = 0.0;
      for (std::size_t i = 0; i < def.spheres.size(); ++i) {
        omega[i] = (def.spheres[i].charge / def.spheres[i].mass) * def.magnetic;
        w_max = std::max(w_max, norm(omega[i]));
      }
      if (w_max > 0.0) cap = 6.283185307179586 / w_max;
      else omega.clear();
      round_off = 0x1p-44 * std::max({size.x, size.y, size.z});
    }
    queue.reset(rec.empty() ? nullptr : &rec[0].node, sizeof(Record), rec.size());
    for (std::uint32_t i = 0; i < rec.size(); ++i) predict(i);
  }

  // Step mode: the end of step k, where every sphere takes its kick. Every count moves, so each
  // pending pair contact is found stale when it comes up; every sphere is predicted anew.
  void kick(double t) {
    now = t;
    for (Record& b : rec) {
      if (!b.alive) continue;
      bring(b, t);
      ++b.count;
    }
    for (std::uint32_t i = 0; i < rec.size(); ++i) {
      if (!rec[i].alive) continue;
      rec[i].v += dt * field_a[i];
      predict(i);
    }
  }
  double step_end(std::uint64_t k) const { return static_cast<double>(k) * dt; }

  // A wall's velocity towards its next key from the pose it has taken (the previous key's, or no
  // shift at t = 0): the chord (shift_next - shift_ref) / (t_next - t_ref); 0 after the last.
  static void aim(Motion& m) {
    if (m.next >= m.keys.size()) {
      m.u = {};
      return;
    }
    const Wall3Key& k = m.keys[m.next];
    m.u = (1.0 / (k.t - m.t_ref)) * (k.shift - m.shift_ref);
  }
  double earliest_key() const {
    double t = kNever;
    for (const Motion& m : motion)
      if (m.next < m.keys.size()) t = std::min(t, m.keys[m.next].t);
    return t;
  }
  // The keyframe at t (== next_key): the walls due take their poses exactly and aim at their next;
  // then every sphere predicts again (a key changes a wall's velocity, so every contact predicted
  // with it is void; O(N), and keys are rare).
  void take_keys(double t) {
    now = t;
    for (Motion& m : motion)
      if (m.next < m.keys.size() && m.keys[m.next].t == t) {
        m.shift_ref = m.keys[m.next].shift;
        m.t_ref = t;
        ++m.next;
        aim(m);
      }
    next_key = earliest_key();
  }
  void predict_all() {
    for (Record& b : rec) ++b.count;  // every pending pair event of the old predictions goes stale
    for (std::uint32_t i = 0; i < rec.size(); ++i)
      if (rec[i].alive) predict(i);
  }
  Vec3 shift_of(std::uint32_t k) const { return k < motion.size() ? motion[k].shift_at(now) : Vec3{}; }
  Vec3 velocity_of(std::uint32_t k) const { return k < motion.size() ? motion[k].u : Vec3{}; }

  // The earliest cell exit of body b (at now) over the three axes.
  double cell_exit(const Record& b, std::uint8_t& axis, std::int8_t& dir) const {
    int k[3];
    coords(b.cell, k);
    double best = kNever;
    for (int a = 0; a < 3; ++a) {
      const double lo = k[a] * w[a], hi = (k[a] + 1 == n[a]) ? size[a] : lo + w[a];
      if (b.a[a] == 0.0) {
        // A straight flight leaves by the face it moves towards (a position past it by
        // round-off leaves at once, as first_approach_quadratic would have it).
        const double va = b.v[a];
        if (va == 0.0) continue;
        const double t = va > 0.0 ? std::max(0.0, (hi - b.x[a]) / va) : std::max(0.0, (lo - b.x[a]) / va);
        if (t < best) { best = t; axis = static_cast<std::uint8_t>(a); dir = va > 0.0 ? 1 : -1; }
        continue;
      }
      // The same cancellation-free forms as the 2-D clock's crossings (toi.cpp).
      const double t_hi = first_approach_quadratic(hi - b.x[a], -b.v[a], -0.5 * b.a[a]);
      const double t_lo = first_approach_quadratic(b.x[a] - lo, b.v[a], 0.5 * b.a[a]);
      if (t_hi < best) { best = t_hi; axis = static_cast<std::uint8_t>(a); dir = 1; }
      if (t_lo < best) { best = t_lo; axis = static_cast<std::uint8_t>(a); dir = -1; }
    }
    return best;
  }

  // Features of wall k against body b (at now), up to best; updates b's pending event.
  // Walls are searched up to the cell exit too: after it, the next cell's list has them.
  void predict_wall(Record& b, std::uint32_t k, double& cand, double exit) {
    double best = std::min(cand, exit);
    const double before = best;
    const Polygon3& p = walls[k];
    const double tol = 1e-12 * p.scale;
    // In the wall's frame (it translates at u, shifted by o from its t = 0 corners) the sphere
    // flies x - o, v - u, a: the same family of flights, against the wall's t = 0 corners.
    const Vec3 x = b.x - shift_of(k), v = b.v - velocity_of(k);
    const Vec3 d = x - p.corners[0];
    double c[5], times[4];
    // The face: the memo's plane formula, both sides (s = r falling, s = -r rising).
    {
      const double s0 = dot(d, p.normal), s1 = dot(v, p.normal), s2 = 0.5 * dot(b.a, p.normal);
      for (int side = -1; side <= 1; side += 2) {
        c[0] = side * s0 - b.r; c[1] = side * s1; c[2] = side * s2;
        const int m = approach_times(c, 2, best, 1e-9 * b.r, times);
        for (int q = 0; q < m; ++q) {
          if (!(times[q] < best)) break;
          if (p.covers(fly(x, v, b.a, times[q]), tol)) {
            best = times[q];
            b.kind = Pending::face; b.partner = k; b.partner_count = 0;
            break;
          }
        }
      }
    }
    const std::size_t nc = p.corners.size();
    for (std::size_t e = 0; e < nc; ++e) {
      // The edge: the cylinder of radius r around its line, where the foot is on the segment.
      const Vec3 u = p.along[e];
      const Vec3 de = x - p.corners[e];
      const Vec3 dp = de - dot(de, u) * u, vp = v - dot(v, u) * u, ap = b.a - dot(b.a, u) * u;
      squared_gap(dp, vp, ap, b.r, c);
      const int m = approach_times(c, 4, best, 1e-9 * b.r * b.r, times);
      for (int q = 0; q < m; ++q) {
        if (!(times[q] < best)) break;
        const double s = dot(fly(de, v, b.a, times[q]), u);
        if (s >= -tol && s <= p.length[e] + tol) {
          best = times[q];
          b.kind = Pending::edge; b.partner = k; b.partner_count = static_cast<std::uint32_t>(e);
          break;
        }
      }
      // The corner: the memo's wall-end formula.
      squared_gap(de, v, b.a, b.r, c);
      const int mc = approach_times(c, 4, best, 1e-9 * b.r * b.r, times);
      if (mc > 0 && times[0] < best) {
        best = times[0];
        b.kind = Pending::corner; b.partner = k; b.partner_count = static_cast<std::uint32_t>(e);
      }
    }
    if (best < before) cand = best;
  }

  // Cell k (column, row, layer) of a neighbourhood brought into the grid: false outside an arena
  // that is not periodic, else wrapped, with `shift` the periodic image's offset.
  bool wrap_cell(int* k, Vec3& shift) const {
    for (int a = 0; a < 3; ++a) {
      if (k[a] >= 0 && k[a] < n[a]) continue;
      if (boundary != Boundary3::periodic) return false;
      shift[a] = k[a] < 0 ? -size[a] : size[a];
      k[a] = (k[a] + n[a]) % n[a];
    }
    return true;
  }

  // The spheres of one cell against b (at now): the earliest approach below cand.
  void scan_cell(std::uint32_t i, Record& b, int cx, int cy, int cz, double& cand) {
    Vec3 shift;
    int k[3] = {cx, cy, cz};
    if (!wrap_cell(k, shift)) return;
    for (std::uint32_t j = head[cell_index(k[0], k[1], k[2])]; j != kNone; j = rec[j].next) {
      if (j == i) continue;
      const Record& o = rec[j];
      const double dt = now - o.t;
      const Vec3 xo = fly(o.x, o.v, o.a, dt) + shift, vo = o.v + dt * o.a;
      const double t = toi_sphere_sphere(xo - b.x, vo - b.v, o.a - b.a, b.r + o.r, cand);
      if (t < cand) {
        cand = t;
        b.kind = Pending::pair; b.partner = j; b.partner_count = o.count;
      }
    }
  }

  void schedule(std::uint32_t i, Record& b, double cand, double exit) {
    b.cand_t = b.kind == Pending::none ? kNever : now + cand;
    b.exit_t = now + exit;
    queue.set(i, std::min(b.cand_t, b.exit_t));
  }

  // A full prediction: the 27 cells around, the walls of the cell, the cell exit. Pairs are
  // searched without a horizon (a pair's time holds whatever cells the two are in), so that a
  // crossing needs to look only at the strip of cells that comes into view.
  void predict(std::uint32_t i) {
    Record& b = rec[i];
    bring(b, now);
    if (!omega.empty()) {
      predict_magnetic(i);
      return;
    }
    const double exit = cell_exit(b, b.axis, b.dir);
    double cand = kNever;
    b.kind = Pending::none;
    int k[3];
    coords(b.cell, k);
    for (int oz = -1; oz <= 1; ++oz)
      for (int oy = -1; oy <= 1; ++oy)
        for (int ox = -1; ox <= 1; ++ox) scan_cell(i, b, k[0] + ox, k[1] + oy, k[2] + oz, cand);
    for (std::uint32_t wk : cell_walls[b.cell]) predict_wall(b, wk, cand, exit);
    schedule(i, b, cand, exit);
  }

  // A prediction in a scene with a magnetic field: every search is bounded by the horizon
  // (the cell exit, at most `cap` ahead, less where a search stopped early); a sphere that reaches
  // it without event predicts again (axis 3: no crossing).
  void predict_magnetic(std::uint32_t i) {
    Record& b = rec[i];
    limit = cap;
    const Path me = path_of(i);
    double exit = me.helix ? helix_exit(b, me) : cell_exit(b, b.axis, b.dir);
    double cand = kNever;
    b.kind = Pending::none;
    int k[3];
    coords(b.cell, k);
    for (int oz = -1; oz <= 1; ++oz)
      for (int oy = -1; oy <= 1; ++oy)
        for (int ox = -1; ox <= 1; ++ox) scan_cell_magnetic(i, me, k[0] + ox, k[1] + oy, k[2] + oz, cand, exit);
    for (std::uint32_t wk : cell_walls[b.cell]) {
      if (me.helix) predict_wall_helix(b, me, wk, cand, std::min(exit, limit));
      else predict_wall(b, wk, cand, std::min(exit, limit));
    }
    if (limit < exit) {  // the horizon (cap, or where a search stopped) comes before the exit
      exit = limit;
      b.axis = 3;
    }
    if (cand > exit) b.kind = Pending::none;
    schedule(i, b, cand, exit);
  }

  // The cell exit of a helix: each of the six faces' distance is linear in the position, so
  // conservative advancement with |x''| finds its crossing (within tol inside the cell).
  double helix_exit(Record& b, const Path& me) {
    int k[3];
    coords(b.cell, k);
    double best = kNever;
    b.axis = 3;
    b.dir = 0;
    for (int a = 0; a < 3; ++a) {
      const double lo = k[a] * w[a], hi = (k[a] + 1 == n[a]) ? size[a] : lo + w[a];
      const double tol = 1e-12 * w[a] + round_off;
      for (int dir = -1; dir <= 1; dir += 2) {
        const double t = touch(
            [&](double s, double& g, double& gd) {
              const double x = me.pos(s)[a];
              const double v = me.vel(s)[a];
              g = dir > 0 ? hi - x : x - lo;
              gd = dir > 0 ? -v : v;
            },
            me.accel(), std::min(best, cap), tol);
        if (t < best) {
          best = t;
          b.axis = static_cast<std::uint8_t>(a);
          b.dir = static_cast<std::int8_t>(dir);
        }
      }
    }
    return best;
  }

  // Wall k against a helix: the distance to the polygon (a convex set, so convex in position) in
  // the wall's frame; the feature is where the nearest point lies at the contact.
  void predict_wall_helix(Record& b, const Path& me, std::uint32_t k, double& cand, double exit) {
    const Polygon3& p = walls[k];
    const Vec3 o = shift_of(k), u = velocity_of(k);
    auto eval = [&](double s, double& g, double& gd) {
      const Vec3 q = me.pos(s) - (o + s * u);
      const Vec3 d = q - p.nearest(q).point;
      const double dist = norm(d);
      g = dist - b.r;
      gd = dist > 0.0 ? dot(d, me.vel(s) - u) / dist : -1.0;
    };
    const double t = touch(eval, me.accel(), std::min(cand, exit), 1e-12 * b.r + round_off);
    if (t < cand) {
      cand = t;
      const Polygon3::Nearest nf = p.nearest(me.pos(t) - (o + t * u));
      b.kind = nf.kind == 0 ? Pending::face : nf.kind == 1 ? Pending::edge : Pending::corner;
      b.partner = k;
      b.partner_count = nf.kind == 0 ? 0 : nf.index;
    }
  }

  // The spheres of one cell against sphere i in a magnetic scene: a pair neither of which
  // gyrates by the closed forms (up to the horizon), else conservative advancement on the
  // distance of centres.
  void scan_cell_magnetic(std::uint32_t i, const Path& me, int cx, int cy, int cz, double& cand, double exit) {
    Record& b = rec[i];
    Vec3 shift;
    int k[3] = {cx, cy, cz};
    if (!wrap_cell(k, shift)) return;
    for (std::uint32_t j = head[cell_index(k[0], k[1], k[2])]; j != kNone; j = rec[j].next) {
      if (j == i) continue;
      const Record& o = rec[j];
      const double horizon = std::min({cand, exit, limit});
      double t;
      if (!me.helix && !gyrates(j)) {
        const double dt = now - o.t;
        const Vec3 xo = fly(o.x, o.v, o.a, dt) + shift, vo = o.v + dt * o.a;
        t = toi_sphere_sphere(xo - b.x, vo - b.v, o.a - b.a, b.r + o.r, horizon);
      } else {
        Path other = path_of(j);
        other.x += shift;
        const double sigma = b.r + o.r;
        t = touch(
            [&](double s, double& g, double& gd) {
              const Vec3 d = other.pos(s) - me.pos(s);
              const double dist = norm(d);
              g = dist - sigma;
              gd = dot(d, other.vel(s) - me.vel(s)) / dist;
            },
            me.accel() + other.accel(), horizon, 1e-12 * std::min(b.r, o.r) + round_off);
      }
      if (t < cand) {
        cand = t;
        b.kind = Pending::pair; b.partner = j; b.partner_count = o.count;
      }
    }
  }

  // After a crossing along `axis` by `dir`: the kept contact candidate (still a true time of
  // its pair if the partner's count has not moved; a stale one is found when popped), the nine
  // cells of the new strip, the new cell's walls, the new exit.
  void predict_strip(std::uint32_t i, int axis, int dir) {
    Record& b = rec[i];
    const double exit = cell_exit(b, b.axis, b.dir);
    double cand = b.kind == Pending::none ? kNever : b.cand_t - now;
    int k[3];
    coords(b.cell, k);
    k[axis] += dir;
    const int u = (axis + 1) % 3, w2 = (axis + 2) % 3;
    for (int ou = -1; ou <= 1; ++ou)
      for (int ow = -1; ow <= 1; ++ow) {
        int c[3];
        c[axis] = k[axis];
        c[u] = k[u] + ou;
        c[w2] = k[w2] + ow;
        scan_cell(i, b, c[0], c[1], c[2], cand);
      }
    for (std::uint32_t wk : cell_walls[b.cell]) predict_wall(b, wk, cand, exit);
    schedule(i, b, cand, exit);
  }

  // The other body's position seen from a, by the minimum image (at contact the pair is closer
  // than half the arena on every axis: cells are at least a diameter and there are 3 or more).
  Vec3 separation(const Record& a, const Record& o) const {
    Vec3 d = o.x - a.x;
    if (boundary == Boundary3::periodic)
      for (int k = 0; k < 3; ++k) d[k] -= size[k] * std::nearbyint(d[k] / size[k]);
    return d;
  }

  void note(Event3Kind kind, std::uint32_t a, std::uint32_t b2, std::uint32_t c) {
    if (log) log->push_back({now, kind, a, b2, c});
  }

  void reflect(Record& b, Vec3 normal) {
    const Vec3 nn = (1.0 / norm(normal)) * normal;
    b.v -= (2.0 * dot(b.v, nn)) * nn;
    ++b.count;
    ++collisions;
  }

  // The TC rule (2-D's Restitution::for_ball): a sphere that changed course less than tc ago
  // collides elastically.
  double e_now(std::uint32_t i) const { return now - last_change[i] < tc ? 1.0 : e_sphere[i]; }

  // The impulse on sphere i along the line of centres n (from i to j) with restitution: the
  // pair's e is the larger of the two spheres' (after the TC rule), the relative normal speed
  // s = -vn leaves as e s, and never slower than kDepartFloor of the relative speed (a sphere
  // pair at e = 0 would otherwise be left touching and "approaching" by round-off).
  double inelastic_pair_impulse(std::uint32_t i, std::uint32_t j, Vec3 w, double vn, double mu) {
    const double e = std::max(e_now(i), e_now(j));
    last_change[i] = last_change[j] = now;
    if (e == 1.0) return 2.0 * mu * vn;
    const double out = std::max(e * -vn, kDepartFloor * norm(w));
    return -mu * (-vn + out);
  }

  // A wall feature's bounce with restitution e_sphere * e_wall: the normal speed w leaves as
  // e w, at least kDepartFloor of the speed, and, where the sphere's acceleration presses it onto
  // the feature (a_n < 0), at least |a_n| tc / 2 (the rest threshold: it stays away for tc at
  // least, so a sphere coming to rest on a floor bounces every tc instead of infinitely often).
  // At e = 1 the plain reflection.
  void bounce_inelastic(std::uint32_t i, Record& b, Vec3 normal, std::uint32_t wall) {
    const double e = e_sphere[i] * e_wall[wall];
    last_change[i] = now;
    if (e == 1.0) {
      reflect(b, normal);
      return;
    }
    const Vec3 nn = (1.0 / norm(normal)) * normal;
    const double w = -dot(b.v, nn);
    double out = std::max(e * w, kDepartFloor * norm(b.v));
    const double a_n = dot(b.a, nn);
    if (a_n < 0.0) out = std::max(out, -a_n * tc / 2.0);
    b.v += (w + out) * nn;
    ++b.count;
    ++collisions;
  }

  void serve(std::uint32_t i) {
    Record& b = rec[i];
    ++events;
    if (b.exit_t < b.cand_t) {
      cross(i);
      return;
    }
    switch (b.kind) {
      case Pending::none: queue.set(i, kNever); return;
      case Pending::pair: {
        Record& o = rec[b.partner];
        if (!o.alive || o.count != b.partner_count) {
          predict(i);
          return;
        }
        bring(b, now);
        bring(o, now);
        const Vec3 d = separation(b, o);
        const double dist = norm(d), sigma = b.r + o.r;
        contact_error = std::max(contact_error, std::abs(dist - sigma) / std::min(b.r, o.r));
        // The memo's vector form: the relative velocity's part along the line of centres is
        // reversed, shared by the masses.
        const Vec3 nn = (1.0 / dist) * d;
        const double vn = dot(o.v - b.v, nn);
        const double mu = b.m * o.m / (b.m + o.m);
        double jn = 2.0 * mu * vn;  // impulse on b along nn
        if (inelastic) jn = inelastic_pair_impulse(i, b.partner, o.v - b.v, vn, mu);
        b.v += (jn / b.m) * nn;
        o.v -= (jn / o.m) * nn;
        virial += -jn * dist;  // m1 m2 / M (Δv12 . r12) with r12 = -d, Δv12 = jn / m nn
        ++b.count;
        ++o.count;
        ++collisions;
        note(Event3Kind::ball_ball, i, b.partner, 0);
        const std::uint32_t j = b.partner;
        predict(i);
        predict(j);
        return;
      }
      case Pending::face: case Pending::edge: case Pending::corner: {
        bring(b, now);
        const Polygon3& p = walls[b.partner];
        Vec3 normal;
        Event3Kind kind;
        const Vec3 x = b.x - shift_of(b.partner);  // in the wall's frame, against its t = 0 corners
        const Vec3 d = x - p.corners[b.partner_count];
        if (b.kind == Pending::face) {
          normal = dot(x - p.corners[0], p.normal) >= 0.0 ? p.normal : -p.normal;  // towards the sphere
          kind = Event3Kind::ball_wall;
          contact_error = std::max(contact_error, std::abs(std::abs(dot(x - p.corners[0], normal)) - b.r) / b.r);
        } else if (b.kind == Pending::edge) {
          const Vec3 u = p.along[b.partner_count];
          normal = d - dot(d, u) * u;
          kind = Event3Kind::ball_wall_edge;
          contact_error = std::max(contact_error, std::abs(norm(normal) - b.r) / b.r);
        } else {
          normal = d;
          kind = Event3Kind::ball_wall_corner;
          contact_error = std::max(contact_error, std::abs(norm(normal) - b.r) / b.r);
        }
        if (motion.empty() && wedge(i, b, b.partner, (1.0 / norm(normal)) * normal)) return;
        const Vec3 v_before = b.v;
        // The bounce in the wall's frame: v' = u + bounce(v - u) (u = 0 for a standing wall).
        const bool moves = !motion.empty();  // else bit for bit the standing walls' bounce
        const Vec3 u = velocity_of(b.partner);
        if (moves) b.v -= u;
        if (inelastic) bounce_inelastic(i, b, normal, b.partner);
        else reflect(b, normal);
        if (moves) {
          b.v += u;
          wall_work += 0.5 * b.m * (norm2(b.v) - norm2(v_before));
        }
        wall_push[b.partner] += b.m * dot(b.v - v_before, normal) / norm(normal);
        note(kind, i, b.partner, b.partner_count);
        predict(i);
        return;
      }
      case Pending::cell: break;
    }
  }

  // The wedge (docs/physics.md, "3-D: wedged spheres"): sphere i (at now) meets standing wall k
  // along n (the unit normal towards it) while touching a standing wall on the other side, -n.
  // If every other contact it has is across n or out of reach, the zero-time sequence of its
  // bounces between the two never ends (a bounce at e > 0 leaves the pair's relative speed e
  // times what it was, never 0, and 0 is the only speed along n that opens both), and its limit
  // is the sphere's velocity without its part along n: taken, booked, logged `wedged`. Out of
  // reach: in that sequence the sphere keeps w, its velocity across n, and |v . n| never grows, so
  // a contact along m (from the sphere) with something of velocity u (a standing wall: 0; a
  // sphere: its own, which nothing else changes in zero time) opens at least at (u - w) . m -
  // |n . m| |v . n|: positive (beyond 1e-9 of the speeds), it never closes. Moving walls: not
  // asked (the caller's test). False, and the bounce is served as usual, otherwise.
  bool wedge(std::uint32_t i, Record& b, std::uint32_t k, Vec3 n) {
    const double touch = 1e-9 * b.r;  // the overlap budget
    const double a = dot(b.v, n);
    const Vec3 w = b.v - a * n;
    const double margin = 1e-9 * (norm(w) + std::abs(a));
    constexpr double kParallel = 1e-9;
    std::uint32_t other = kNone;
    bool reach_ok = true;
    // A contact along m (unit, from the sphere) with something moving at u; `standing`: a wall.
    auto asks = [&](Vec3 m, Vec3 u, bool standing) {
      const double c = dot(n, m);
      if (std::abs(c) <= kParallel) return;  // across
      if (std::abs(c) >= 1.0 - kParallel) {
        // In line: a standing wall on either side is the pair's; a sphere in line is a row (2-D's
        // jammed chain), not this rule.
        if (!standing) reach_ok = false;
        return;
      }
      if (!(dot(u - w, m) - std::abs(c) * std::abs(a) > margin)) reach_ok = false;
    };
    for (const std::uint32_t q : cell_walls[b.cell]) {
      if (q == k) continue;
      const Vec3 d = walls[q].nearest(b.x).point - b.x;
      const double dist = norm(d);
      if (!(dist > 0.0) || dist - b.r > touch) continue;
      const Vec3 m = (1.0 / dist) * d;
      if (dot(n, m) >= 1.0 - kParallel && other == kNone) other = q;  // on the far side
      asks(m, Vec3{}, true);
    }
    if (other == kNone || !reach_ok) return false;
    int c[3];
    coords(b.cell, c);
    for (int dz = -1; dz <= 1 && reach_ok; ++dz)
      for (int dy = -1; dy <= 1 && reach_ok; ++dy)
        for (int dx = -1; dx <= 1 && reach_ok; ++dx) {
          int q[3] = {c[0] + dx, c[1] + dy, c[2] + dz};
          Vec3 shift;
          if (!wrap_cell(q, shift)) continue;
          for (std::uint32_t j = head[cell_index(q[0], q[1], q[2])]; j != kNone; j = rec[j].next) {
            if (j == i) continue;
            const Record& o = rec[j];
            const double dt = now - o.t;
            const Vec3 d = pos_at(o, dt) + shift - b.x;
            const double dist = norm(d);
            if (!(dist > 0.0) || dist - (b.r + o.r) > touch) continue;
            asks((1.0 / dist) * d, vel_at(o, dt), false);
          }
        }
    if (!reach_ok) return false;
    energy_wedged += 0.5 * b.m * a * a;
    ++wedged;
    b.v = w;
    ++b.count;
    note(Event3Kind::wedged, i, k, other);
    predict(i);
    return true;
  }

  void cross(std::uint32_t i) {
    Record& b = rec[i];
    bring(b, now);
    if (b.axis == 3) {  // a magnetic scene's horizon: predict again, no crossing
      predict(i);
      return;
    }
    int k[3];
    coords(b.cell, k);
    const int a = b.axis, dir = b.dir;
    k[a] += dir;
    if (k[a] < 0 || k[a] >= n[a]) {
      if (boundary != Boundary3::periodic) {
        unlink(i);
        b.alive = false;
        ++b.count;
        queue.remove(i);
        note(Event3Kind::exit, i, 0, 0);
        return;
      }
      k[a] = (k[a] + n[a]) % n[a];
      b.x[a] -= dir * size[a];
    }
    unlink(i);
    link(i, cell_index(k[0], k[1], k[2]));
    if (!omega.empty()) predict(i);  // searches are bounded there: the whole neighbourhood again
    else predict_strip(i, a, dir);
  }

  void serve_until(double t) {
    while (!queue.empty() && queue.top_key() <= t) {
      if (events >= next_check) check_stop();
      const std::uint32_t i = queue.top_id();
      now = queue.top_key();
      serve(i);
    }
  }

  void advance_to(double t) {
    // Step mode: the contacts of a step (up to and at its end), then the kick. A moving wall's
    // key: the contacts up to and at it, then the walls' new courses and every sphere predicted
    // again (by the kick, when a step ends at the same instant).
    for (;;) {
      const double step = field_a.empty() ? kNever : step_end(steps + 1);
      const double stop = std::min(step, next_key);
      if (!(stop <= t)) break;
      serve_until(stop);
      if (stop == next_key) take_keys(stop);
      if (stop == step) kick(step_end(++steps));
      else predict_all();
    }
    serve_until(t);
    now = t;
  }

  // The acceleration the fields give sphere i (step mode keeps it beside the straight flight).
  Vec3 accel(std::size_t i) const { return field_a.empty() ? rec[i].a : field_a[i]; }
};

void World3::set_event_limit(std::uint64_t limit) {
  impl_->event_limit = limit;
  impl_->arm_check();
}
void World3::set_stop_poll(std::function<bool()> poll, std::uint64_t every) {
  impl_->stop_poll = std::move(poll);
  impl_->poll_every = std::max<std::uint64_t>(1, every);
  impl_->arm_check();
}
std::uint64_t World3::wedged() const { return impl_->wedged; }
double World3::energy_wedged() const { return impl_->energy_wedged; }

World3::World3(const World3Def& def) {
  const std::string problem = check_world3(def);
  if (!problem.empty()) throw std::invalid_argument(problem);
  impl_ = std::make_unique<Impl>(def);
}
World3::~World3() = default;
World3::World3(World3&&) noexcept = default;
World3& World3::operator=(World3&&) noexcept = default;

void World3::advance_to(double t, std::vector<Event3>* log) {
  impl_->log = log;
  try {
    impl_->advance_to(std::max(t, impl_->now));
  } catch (...) {
    impl_->log = nullptr;
    throw;
  }
  impl_->log = nullptr;
}
double World3::time() const { return impl_->now; }
std::size_t World3::sphere_count() const { return impl_->rec.size(); }
bool World3::alive(std::size_t i) const { return impl_->rec[i].alive; }
Vec3 World3::position(std::size_t i) const {
  const Record& b = impl_->rec[i];
  return impl_->pos_at(b, impl_->now - b.t);
}
Vec3 World3::velocity(std::size_t i) const {
  const Record& b = impl_->rec[i];
  return impl_->vel_at(b, impl_->now - b.t);
}
std::size_t World3::wall_count() const { return impl_->walls.size(); }
double World3::kinetic_energy() const {
  double e = 0.0;
  for (std::size_t i = 0; i < impl_->rec.size(); ++i)
    if (impl_->rec[i].alive) e += 0.5 * impl_->rec[i].m * norm2(velocity(i));
  return e;
}
double World3::energy() const {
  double e = kinetic_energy();
  for (std::size_t i = 0; i < impl_->rec.size(); ++i)
    if (impl_->rec[i].alive) e -= impl_->rec[i].m * dot(impl_->accel(i), position(i));
  return e;
}
Vec3 World3::momentum() const {
  Vec3 p;
  for (std::size_t i = 0; i < impl_->rec.size(); ++i)
    if (impl_->rec[i].alive) p += impl_->rec[i].m * velocity(i);
  return p;
}
std::uint64_t World3::collisions() const { return impl_->collisions; }
std::uint64_t World3::events() const { return impl_->events; }
double World3::max_contact_error() const { return impl_->contact_error; }
double World3::virial_sum() const { return impl_->virial; }
double World3::wall_push(std::size_t w) const { return impl_->wall_push.at(w); }
Vec3 World3::wall_shift(std::size_t w) const { return impl_->shift_of(static_cast<std::uint32_t>(w)); }
double World3::wall_work() const { return impl_->wall_work; }
double World3::wall_area(std::size_t w) const {
  const std::vector<Vec3>& c = impl_->walls.at(w).corners;
  Vec3 twice;  // Newell's: twice the area along the normal, for any planar polygon
  for (std::size_t k = 0; k < c.size(); ++k) twice += cross(c[k], c[(k + 1) % c.size()]);
  return 0.5 * norm(twice);
}

double World3::max_overlap_now() const {
  const Impl& m = *impl_;
  std::array<double, 3> period{};
  if (m.boundary == Boundary3::periodic)
    for (int a = 0; a < 3; ++a) period[a] = m.size[a];
  detail::Overlap3Scratch scratch;
  return detail::deepest_overlap3(
      scratch, m.rec.size(), [&](std::size_t i) { return position(i); }, [&](std::size_t i) { return m.rec[i].r; },
      [&](std::size_t i) { return m.rec[i].alive; }, period, [&](std::uint32_t i, const Vec3& x) {
        double worst = 0.0;
        for (std::uint32_t k = 0; k < m.walls.size(); ++k)
          worst = std::max(worst, (m.rec[i].r - m.walls[k].distance(x - m.shift_of(k))) / m.rec[i].r);
        return worst;
      });
}

}  // namespace turtlegas::sim
