// SPDX-License-Identifier: MIT
// EngineState: the whole memory of a gas engine as plain data (World::save_state and
// World::restore_state), for a checkpoint that resumes a run without replaying it.
//
// Why more than positions and velocities. The engine's future depends on what it has cached, not
// only on where the balls are: each body keeps its own clock (a ball is moved only when an event
// touches it, so its position is x + v (now - t) rounded when next needed, not a value brought to
// now), its pending prediction (the earliest collision and cell exit, with the partner's course
// counter that makes it stale), the order of the cell lists (which breaks ties between candidates
// of equal time), the partner it met last (a pair that has just collided is not predicted again),
// the squeeze rule's marks, the TC rule's clocks, a sliding ball's wall, the rebase count and the
// step's bookkeeping. A world rebuilt from positions and velocities brought to one time predicts
// afresh from rounded positions and continues a different run in the last bits within a few
// thousand events. So this holds all of it, bit for bit; the queue is rebuilt from the keys, which
// alone decide its order of service (ties by id, event_queue.hpp).
//
// What it is not: an interchange format. It is meaningful only to a World built from the same
// scene, in the same mode, by the same build of the engine (the variant name is checked). Scenes
// with turtles, collision layers or moving walls (the engine's extras) are not saved: their
// turtles' programs cannot be written down anyway (docs/controllers.md, "Checkpoints").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "turtlegas/sim/vec2.hpp"
#include "turtlegas/sim/world_stats.hpp"

namespace turtlegas::sim {

struct EngineState {
  /// The engine row that saved it (flight, ball pairs, mode): restore_state refuses another.
  std::string variant;
  double now = 0.0;     ///< internal time, relative to t_base (seconds)
  double t_base = 0.0;  ///< external time of internal time zero (seconds)
  std::uint64_t events_since_rebase = 0;
  std::size_t walls = 0;  ///< how many walls the engine had (scene, arena, added): checked on restore

  /// One body's record: its state at its own time t, its cell-list links and its prediction.
  struct Body {
    Vec2 x, v;
    double t = 0.0;  ///< internal time of x and v
    std::uint32_t count = 0, cell = 0, next = 0, prev = 0;
    double t_coll = 0.0, t_cross = 0.0;
    std::uint32_t partner = 0, partner_count = 0;
    std::uint32_t last = 0;  ///< the last partner, packed (kind and index)
    std::uint8_t kind = 0, cross_dir = 0;
    bool queued = false;  ///< whether it is in the event queue, and with which key (maybe infinite)
    double key = 0.0;
  };
  std::vector<Body> bodies;

  /// The squeeze rule's marks (empty until a body is first held); partners packed as `last`.
  struct Held {
    std::uint32_t a = 0, b = 0, count = 0, count_a = 0, count_b = 0;
    bool straight = false;
    double t = 0.0;
  };
  std::vector<Held> held;
  /// The TC rule: per body, the internal time it last changed course (only when e < 1).
  std::vector<double> last_time;
  /// Sliding balls under gravity, by ball index (grown at a ball's first slide); wall ~0u: none.
  struct Slide {
    Vec2 a, p1, u, n, p2;
    double len = 0.0;
    std::uint32_t wall = 0;
  };
  std::vector<Slide> slides;

  /// Step mode: steps done, the step's largest path, the scan counter and stamps, each body's path.
  std::uint64_t step_index = 0;
  double step_dmax = 0.0;
  std::uint32_t step_scan = 0;
  std::vector<std::uint32_t> step_stamp;
  std::vector<double> step_travel;

  Stats stats;
  Overlap max_contact;
  std::vector<double> energy_taken;
};

}  // namespace turtlegas::sim
