// SPDX-License-Identifier: MIT
#include "check_command.hpp"

#include <cstdio>
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "cli_common.hpp"
#include "run3d.hpp"
#include "scene_scales.hpp"

namespace turtlegas::apps {
namespace {

int check_one(const std::string& file, const turtle::Registry& registry) {
  if (const auto w3 = load_world3_if_3d(file)) return check3d(file, *w3);
  const world::Scene scene = load(file, registry);
  const sim::WorldDef& def = scene.def;
  // One engine at a time: a scene near the memory budget must not need two of it at once (an
  // explicit "cell": 1 over 14000 x 14000 took 3 GB when both were built together).
  double cell_size = 0.0;
  int cells_x = 0, cells_y = 0;
  std::vector<std::string> warnings;
  for (sim::Mode mode : {sim::Mode::exact, sim::Mode::step}) {
    const sim::World world = make_world(def, mode, file);
    if (mode == sim::Mode::step) cell_size = world.cell_size(), cells_x = world.cells_x(), cells_y = world.cells_y();
    // How much work the scene's scales predict (scene_scales.hpp), over its expect list's run or
    // one simulated second.
    SceneScales scales = predict_scales(def, mode);
    scales.set_cell(world.cell_size());
    const double seconds = scene.expect.until.value_or(1.0);
    const std::string span = std::string(sim::to_string(mode)) + " mode: " +
                             (scene.expect.until ? "the expect list's run to until " + fmt(seconds)
                                                 : std::string("one simulated second"));
    for (std::string& w : scale_warnings(scales, seconds, span)) warnings.push_back(std::move(w));
  }
  if (std::optional<std::string> w = precision_warning(def)) warnings.push_back(std::move(*w));
  std::printf("%s: ok: \"%s\", %s, arena %s x %s (boundary %s), cell %s (%d x %d), dt %s s\n", file.c_str(),
              def.name.c_str(), count_summary(def, def.balls.size()).c_str(), fmt(def.arena.width).c_str(),
              fmt(def.arena.height).c_str(), sim::to_string(def.arena.boundary).data(), fmt(cell_size).c_str(), cells_x, cells_y,
              fmt(def.dt).c_str());
  for (const std::string& w : warnings) spdlog::warn("{}: {}", file, w);
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
