// SPDX-License-Identifier: MIT
// A gas's trajectory as extended XYZ (`turtlegas run --xyz F --xyz-every DT`, docs/cli.md): one
// frame per DT of simulated time, each the number of balls alive, a comment line with the frame's
// time, the arena as the lattice and the columns, then one line per ball. OVITO and ASE read the
// extended header (types, velocities, radii, the periodic cell); VMD and other plain XYZ readers take
// the first four columns (type x y z) and the comment as a comment.
#pragma once

#include <ostream>

#include "turtlegas/formats/names.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::formats {

class XyzWriter {
 public:
  /// Frames of `world`'s balls, named by `ids`, written to `out` (which must outlive the writer).
  /// The balls' types are their species: balls of one radius and mass, "A", "B", ... in the order
  /// they first appear (after "Z", "T26", "T27", ...).
  XyzWriter(std::ostream& out, const sim::World& world, const sim::WorldDef& def, const IdTable& ids);
  /// Writes one frame of the world as it is now (its time in the comment line). Positions as the
  /// engine has them: inside the cell in a periodic arena (pbc="T T F"), x y 0; numbers in their
  /// shortest form that reads back to the same double.
  void frame(const sim::World& world);
  std::size_t frames() const { return frames_; }

 private:
  std::ostream* out_;
  const IdTable* ids_;
  std::string cell_;                  ///< Lattice=... pbc=...
  std::vector<std::string> type_of_;  ///< per ball
  std::size_t frames_ = 0;
};

}  // namespace turtlegas::formats
