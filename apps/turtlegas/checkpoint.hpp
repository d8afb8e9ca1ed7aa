// SPDX-License-Identifier: MIT
// `run --checkpoint F` and `run --resume F`: what a checkpoint holds, and reading and writing one.
//
// A checkpoint holds a run's inputs and how far it got: the world file's hash, the mode and dt,
// the time reached, and the hash of the state and the event count there. For a gas (no turtles,
// layers or moving walls) it holds the engine's whole memory as well (`engine`, formats/
// engine_state.hpp): `--resume` builds the world from the world file, puts that memory in, checks
// that it is at the checkpoint's state, and goes on, without simulating the time before. A world
// with turtles cannot be written down: programs are coroutines, whose stacks no file can hold; so
// `--resume` rebuilds the run from the world file and replays it, without writing anything, to the
// checkpoint's time (determinism makes that the same run, bit for bit), checks that it arrived at
// the same state, and carries on from there. Either way the resumed run is exactly the run that
// was interrupted (docs/controllers.md, "Checkpoints").
#pragma once

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>

#include "turtlegas/sim/engine_state.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/sim/world_def.hpp"

namespace turtlegas::apps {

/// A checkpoint file, format turtlegas-checkpoint/1.
struct Checkpoint {
  std::string world;               ///< the world file, as given
  std::uint64_t world_hash = 0;    ///< FNV-1a of its bytes
  sim::Mode mode = sim::Mode::exact;
  double dt = 0.0;                 ///< seconds, the run's (after --dt)
  double t = 0.0;                  ///< seconds: the time the run had reached
  std::uint64_t events = 0;        ///< the engine's event count there
  std::uint64_t state_hash = 0;    ///< FNV-1a of the state file there (formats/state_file.hpp)
  std::string why;                 ///< "every 10 s", "SIGINT", "max-events", ...
  /// The engine's whole memory there, for a gas (World::save_state); none for a world with turtles,
  /// which --resume replays.
  std::optional<sim::EngineState> engine;
  /// With an engine state: the turtlegas that wrote it ("0.1.0 <commit>"; engine_build()). Another
  /// build's engine may keep its memory otherwise, so --resume replays instead of using it.
  std::string engine_build;
};

/// This turtlegas, as a checkpoint's engine_build names it: the version and the commit built.
std::string engine_build();

/// 64-bit FNV-1a.
std::uint64_t fnv1a64(std::string_view bytes);
/// FNV-1a of a file's bytes; BadInput naming `what` when it cannot be read.
std::uint64_t file_hash(const std::string& path, const std::string& what);

void write_checkpoint(std::ostream& out, const Checkpoint& c);
/// Reads a checkpoint; BadInput (naming the file and the key) for one that is not.
Checkpoint read_checkpoint(const std::string& path);

}  // namespace turtlegas::apps
