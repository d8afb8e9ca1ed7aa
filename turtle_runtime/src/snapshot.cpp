// SPDX-License-Identifier: MIT
// WorldServer::snapshot and restore: a copy of a world without turtles (world_server.hpp).
#include <algorithm>
#include <memory>
#include <vector>

#include "server_impl.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::turtle {

struct WorldServer::Snapshot {
  sim::WorldDef def;
  sim::World world;
  std::vector<sim::Event> sim_log;
  std::uint64_t step = 0;
  bool boundary_done = false;
  std::vector<View> views;
  std::uint64_t views_revision = 0;
};

std::shared_ptr<const WorldServer::Snapshot> WorldServer::snapshot() const {
  const Impl& s = *impl_;
  if (!s.agents.empty() || s.world.turtle_count() > 0 || s.game) return nullptr;
  return std::make_shared<const Snapshot>(
      Snapshot{s.def, s.world.copy(), s.sim_log, s.step, s.boundary_done, s.views, s.views_revision});
}

void WorldServer::restore(const Snapshot& snap) {
  Impl& s = *impl_;
  s.def = snap.def;
  s.world = snap.world.copy();
  s.world.set_event_log(&s.sim_log);
  s.sim_log = snap.sim_log;
  s.step = snap.step;
  s.boundary_done = snap.boundary_done;
  s.views = snap.views;
  // The views may differ from the ones shown: frames must send them again.
  s.views_revision = std::max(s.views_revision, snap.views_revision) + 1;
}

}  // namespace turtlegas::turtle
