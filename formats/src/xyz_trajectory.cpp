// SPDX-License-Identifier: MIT
#include "turtlegas/formats/xyz_trajectory.hpp"

#include <algorithm>
#include <charconv>
#include <string>
#include <utility>
#include <vector>

namespace turtlegas::formats {
namespace {

/// Shortest decimal that reads back to the same double (std::to_chars, no locale).
void put(std::string& s, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
}

std::string type_name(std::size_t k) {
  if (k < 26) return std::string(1, static_cast<char>('A' + k));
  return "T" + std::to_string(k);
}

}  // namespace

XyzWriter::XyzWriter(std::ostream& out, const sim::World& world, const sim::WorldDef& def, const IdTable& ids)
    : out_(&out), ids_(&ids) {
  std::vector<std::pair<double, double>> species;
  double r_max = 0.0;
  for (std::size_t i = 0; i < world.ball_count(); ++i) {
    const std::pair<double, double> key{world.radius(i), world.mass(i)};
    auto it = std::find(species.begin(), species.end(), key);
    if (it == species.end()) it = species.insert(species.end(), key);
    type_of_.push_back(type_name(static_cast<std::size_t>(it - species.begin())));
    r_max = std::max(r_max, key.first);
  }
  // The cell: the arena, and a third axis one diameter thick (OVITO wants three independent
  // vectors); periodic in x and y when the arena is.
  const bool periodic = def.arena.boundary == sim::Boundary::periodic;
  cell_ = "Lattice=\"";
  put(cell_, def.arena.width);
  cell_ += " 0 0 0 ";
  put(cell_, def.arena.height);
  cell_ += " 0 0 0 ";
  put(cell_, r_max > 0.0 ? 2.0 * r_max : 1.0);
  cell_ += periodic ? "\" pbc=\"T T F\"" : "\" pbc=\"F F F\"";
}

void XyzWriter::frame(const sim::World& world) {
  std::size_t alive = 0;
  for (std::size_t i = 0; i < world.ball_count(); ++i) alive += world.ball(i).alive ? 1 : 0;
  std::string s = std::to_string(alive) + "\n" + cell_ +
                  " Properties=species:S:1:pos:R:3:velo:R:3:radius:R:1:mass:R:1:id:S:1 Time=";
  put(s, world.time());
  s += '\n';
  for (std::size_t i = 0; i < world.ball_count(); ++i) {
    const sim::BallState b = world.ball(i);
    if (!b.alive) continue;
    s += type_of_[i];
    s += ' ';
    put(s, b.pos.x);
    s += ' ';
    put(s, b.pos.y);
    s += " 0 ";
    put(s, b.vel.x);
    s += ' ';
    put(s, b.vel.y);
    s += " 0 ";
    put(s, world.radius(i));
    s += ' ';
    put(s, world.mass(i));
    s += ' ';
    s += (*ids_)[i];
    s += '\n';
  }
  *out_ << s;
  ++frames_;
}

}  // namespace turtlegas::formats
