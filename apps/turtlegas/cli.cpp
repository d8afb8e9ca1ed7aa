// SPDX-License-Identifier: MIT
#include "cli.hpp"

#include <cstdlib>
#include <exception>
#include <ostream>

#include <spdlog/spdlog.h>

#include "check_command.hpp"
#include "cli_common.hpp"
#include "controllers_command.hpp"
#include "plugins.hpp"
#include "version_info.hpp"

namespace turtlegas::apps {

CommandLine::CommandLine() {
  app.require_subcommand(1);
  {
    std::string version = version_text();
    version.pop_back();  // CLI11 adds the newline
    app.set_version_flag("--version", version, "Print the version, the commit, the build type and the compiler, and exit");
  }
  const char* plugin_help = "Load controllers from this shared-library plugin (repeatable)";
  add_run_command(app, run_line, plugins, plugin_help);  // `turtlegas run` (run_command.hpp)

  check = app.add_subcommand("check", "Load and validate world files, and build each in both modes");
  check->add_option("worlds", check_worlds, "World files (format turtlegas-world/1)")->required();
  check->add_option("--plugin", plugins, plugin_help);

  list = app.add_subcommand("controllers", "List the controllers world files can name, with their params");
  list->add_option("--plugin", plugins, plugin_help);

  test = add_test_command(app, test_opt);  // test_command.hpp
  test->add_option("--plugin", plugins, plugin_help);
  tag = add_tag_command(app, tag_opt);  // tag_command.hpp
  tag->add_option("--plugin", plugins, plugin_help);
  serve = add_serve_command(app, serve_opt);  // serve_command.hpp
  serve->add_option("--plugin", plugins, plugin_help);
  replay = add_replay_command(app, replay_opt);
  replay->add_option("--plugin", plugins, plugin_help);
  render = add_render_command(app, render_opt);  // render_command.hpp
  render->add_option("--plugin", plugins, plugin_help);
  sweep = add_sweep_command(app, sweep_opt);  // sweep_command.hpp
  sweep->add_option("--plugin", plugins, plugin_help);
}

Command CommandLine::command() const {
  if (*list) return Command::controllers;
  if (*check) return Command::check;
  if (*test) return Command::test;
  if (*tag) return Command::tag;
  if (*serve) return Command::serve;
  if (*replay) return Command::replay;
  if (*render) return Command::render;
  if (*sweep) return Command::sweep;
  return Command::run;
}

std::optional<int> parse(CommandLine& line, int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  try {
    line.app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return line.app.exit(e, out, err) == 0 ? exit_ok : exit_bad_input;
  }
  return std::nullopt;
}

int dispatch(const CommandLine& line, turtle::Registry& registry) {
  try {
    // The environment's plugins first (docs/controllers.md), then the command line's; a file named
    // by both is loaded once.
    load_plugins(plugin_path_entries(std::getenv("TURTLEGAS_PLUGIN_PATH")), registry, "TURTLEGAS_PLUGIN_PATH");
    load_plugins(line.plugins, registry);
    // Then the plugins the input names: a world file's "plugins", a recording's.
    std::vector<std::string> inputs;
    switch (line.command()) {
      case Command::check: inputs = line.check_worlds; break;
      case Command::test: inputs = line.test_opt.worlds; break;
      case Command::tag: inputs = {line.tag_opt.world}; break;
      case Command::serve: inputs = {line.serve_opt.world}; break;
      case Command::replay: inputs = {line.replay_opt.replay}; break;
      case Command::render: inputs = {line.render_opt.input}; break;
      case Command::run: inputs = {line.run_line.options().world}; break;
      case Command::sweep: load_sweep_plugins(line.sweep_opt.spec, registry); break;
      case Command::controllers: break;
    }
    for (const std::string& input : inputs) load_input_plugins(input, registry);
    switch (line.command()) {
      case Command::controllers: return controllers_command(registry);
      case Command::check: return check_command(line.check_worlds, registry);
      case Command::test: return test_command(line.test_opt, registry, line.plugins);
      case Command::tag: return run_tag_command(line.tag_opt, registry);
      case Command::serve: return serve_command(line.serve_opt, registry);
      case Command::replay: return serve_command(line.replay_opt, registry);
      case Command::render: return render_command(line.render_opt, registry);
      case Command::sweep: return sweep_command(line.sweep_opt, registry, line.plugins);
      case Command::run: break;
    }
    return run_command(line.run_line.options(), registry);
  } catch (const BadInput& e) {
    spdlog::error("{}", e.what());
    return exit_bad_input;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return exit_failure;
  }
}

}  // namespace turtlegas::apps
