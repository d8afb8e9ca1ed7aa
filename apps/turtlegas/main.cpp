// SPDX-License-Identifier: MIT
// The turtlegas command-line program: `turtlegas run`, `check`, `controllers`, `test`, `tag` and `sweep`,
// one file each (see design.md, "Command line", for the contract they keep). This file parses the
// command line and hands over.
#include <exception>
#include <string>
#include <vector>
#if defined(__GLIBC__)  // known once a library header is in
#include <malloc.h>     // mallopt
#endif

#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "check_command.hpp"
#include "cli_common.hpp"
#include "controllers_command.hpp"
#include "plugins.hpp"
#include "render_command.hpp"
#include "run_command.hpp"
#include "serve_command.hpp"
#include "sweep_command.hpp"
#include "tag_command.hpp"
#include "test_command.hpp"
#include "version_info.hpp"
#include "turtlegas/controllers/registry.hpp"

namespace turtlegas::apps {
namespace {

int run(int argc, char** argv) {
#if defined(__GLIBC__)
  // Arrays above 128 KiB come from mmap and go back to the system when freed. glibc otherwise
  // raises this threshold after the first large free, and the loader's freed arrays would stay
  // resident as holes in the heap under the engine's (see docs/performance.md, "Memory").
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
#endif
  auto log = spdlog::stderr_color_st("turtlegas");
  log->set_pattern("%^%l%$: %v");
  spdlog::set_default_logger(log);

  CLI::App app{"turtlegas: a 2-D gas of discs and walls, and turtles with touch sensors (after MIT AI Memo 272)"};
  app.require_subcommand(1);
  {
    std::string version = version_text();
    version.pop_back();  // CLI11 adds the newline
    app.set_version_flag("--version", version, "Print the version, the commit, the build type and the compiler, and exit");
  }

  std::vector<std::string> plugins;
  const char* plugin_help = "Load controllers from this shared-library plugin (repeatable)";
  RunCommandLine run_line;  // `turtlegas run` (run_command.hpp)
  add_run_command(app, run_line, plugins, plugin_help);

  std::vector<std::string> check_worlds;
  CLI::App* check = app.add_subcommand("check", "Load and validate world files, and build each in both modes");
  check->add_option("worlds", check_worlds, "World files (format turtlegas-world/1)")->required();
  check->add_option("--plugin", plugins, plugin_help);

  CLI::App* list = app.add_subcommand("controllers", "List the controllers world files can name, with their params");
  list->add_option("--plugin", plugins, plugin_help);

  TestOptions test_opt;  // `turtlegas test` (test_command.hpp)
  CLI::App* test = add_test_command(app, test_opt);
  test->add_option("--plugin", plugins, plugin_help);

  TagCommandOptions tag_opt;  // `turtlegas tag` (tag_command.hpp)
  CLI::App* tag = add_tag_command(app, tag_opt);
  tag->add_option("--plugin", plugins, plugin_help);

  ServeCommandOptions serve_opt;  // `turtlegas serve` (serve_command.hpp)
  CLI::App* serve = add_serve_command(app, serve_opt);
  serve->add_option("--plugin", plugins, plugin_help);
  ServeCommandOptions replay_opt;  // `turtlegas replay` (serve_command.hpp)
  CLI::App* replay = add_replay_command(app, replay_opt);
  replay->add_option("--plugin", plugins, plugin_help);
  RenderOptions render_opt;  // `turtlegas render` (render_command.hpp)
  CLI::App* render = add_render_command(app, render_opt);
  render->add_option("--plugin", plugins, plugin_help);
  SweepOptions sweep_opt;  // `turtlegas sweep` (sweep_command.hpp)
  CLI::App* sweep = add_sweep_command(app, sweep_opt);
  sweep->add_option("--plugin", plugins, plugin_help);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? exit_ok : exit_bad_input;
  }

  try {
    turtle::Registry registry = controllers::builtin_registry();
    load_plugins(plugins, registry);
    if (*list) return controllers_command(registry);
    if (*check) return check_command(check_worlds, registry);
    if (*test) return test_command(test_opt, registry, plugins);
    if (*tag) return run_tag_command(tag_opt, registry);
    if (*serve) return serve_command(serve_opt, registry);
    if (*replay) return serve_command(replay_opt, registry);
    if (*render) return render_command(render_opt, registry);
    if (*sweep) return sweep_command(sweep_opt, registry, plugins);
    return run_command(run_line.options(), registry);
  } catch (const BadInput& e) {
    spdlog::error("{}", e.what());
    return exit_bad_input;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return exit_failure;
  }
}

}  // namespace
}  // namespace turtlegas::apps

int main(int argc, char** argv) { return turtlegas::apps::run(argc, argv); }
