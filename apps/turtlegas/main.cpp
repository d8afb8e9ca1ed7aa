// SPDX-License-Identifier: MIT
// The turtlegas command-line program: `turtlegas run`, `check`, `controllers`, `test`, `tag`, `serve`,
// `replay`, `render` and `sweep`, one file each (see design.md, "Command line", for the contract they
// keep). The command line itself is cli.cpp; this file sets up the process and hands over.
#include <iostream>
#include <memory>
#if defined(__GLIBC__)  // known once a library header is in
#include <malloc.h>     // mallopt
#endif

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "cli.hpp"
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

  const auto line = std::make_unique<CommandLine>();
  if (const auto done = parse(*line, argc, argv, std::cout, std::cerr)) return *done;
  turtle::Registry registry = controllers::builtin_registry();
  return dispatch(*line, registry);
}

}  // namespace
}  // namespace turtlegas::apps

int main(int argc, char** argv) { return turtlegas::apps::run(argc, argv); }
