// SPDX-License-Identifier: MIT
#include "check_command.hpp"

#include <cstdio>

#include "cli_common.hpp"

namespace turtlegas::apps {

int check_command(const std::string& file, const turtle::Registry& registry) {
  const world::Scene scene = load(file, registry);
  const sim::WorldDef& def = scene.def;
  const sim::World exact = make_world(def, sim::Mode::exact, file);
  const sim::World step = make_world(def, sim::Mode::step, file);
  std::printf("%s: ok: \"%s\", %s, arena %s x %s (boundary %s), cell %s (%d x %d), dt %s s\n", file.c_str(),
              def.name.c_str(), count_summary(def, def.balls.size()).c_str(), fmt(def.arena.width).c_str(), fmt(def.arena.height).c_str(),
              boundary_name(def.arena.boundary), fmt(step.cell_size()).c_str(), step.cells_x(), step.cells_y(),
              fmt(def.dt).c_str());
  if (!def.turtles.empty()) {
    // Building the servers checks what only the runtime knows (controllers, sensors); no program
    // runs until the first control step, so this costs nothing.
    for (sim::Mode mode : {sim::Mode::exact, sim::Mode::step}) {
      turtle::ServerOptions options;
      options.mode = mode;
      make_server(scene, registry, options, file);
    }
    std::printf("  turtles: %s; controllers: %s\n",
                [&] {
                  std::string ids;
                  constexpr std::size_t shown = 8;
                  for (std::size_t i = 0; i < def.turtles.size() && i < shown; ++i)
                    ids += (i ? ", " : "") + def.turtles[i].id;
                  if (def.turtles.size() > shown) ids += ", ... (" + std::to_string(def.turtles.size()) + " in all)";
                  return ids;
                }()
                    .c_str(),
                controller_summary(scene).c_str());
  }
  return exit_ok;
}

}  // namespace turtlegas::apps
