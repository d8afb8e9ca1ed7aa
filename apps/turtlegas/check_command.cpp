// SPDX-License-Identifier: MIT
#include "check_command.hpp"

#include <cstdio>
#include <exception>

#include <spdlog/spdlog.h>

#include "cli_common.hpp"

namespace turtlegas::apps {
namespace {

int check_one(const std::string& file, const turtle::Registry& registry) {
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

}  // namespace

int check_command(const std::vector<std::string>& files, const turtle::Registry& registry) {
  int worst = exit_ok;
  std::size_t bad = 0;
  for (const std::string& file : files) {
    int rc = exit_ok;
    try {
      rc = check_one(file, registry);
    } catch (const BadInput& e) {
      spdlog::error("{}", e.what());
      rc = exit_bad_input;
    } catch (const std::exception& e) {
      spdlog::error("{}: {}", file, e.what());
      rc = exit_failure;
    }
    std::fflush(stdout);
    bad += rc == exit_ok ? 0 : 1;
    // Bad input outranks any other failure, as in `turtlegas test`.
    if (rc == exit_bad_input || (rc != exit_ok && worst == exit_ok)) worst = rc;
  }
  if (files.size() > 1) std::printf("%zu of %zu world files ok\n", files.size() - bad, files.size());
  return worst;
}

}  // namespace turtlegas::apps
