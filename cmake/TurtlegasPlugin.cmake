# turtlegas_add_plugin(NAME source...): a controller plugin for `turtlegas run --plugin` (and check,
# test, tag, sweep, controllers): a shared module lib<NAME>.so that registers its controllers from
# `extern "C" void turtlegas_register(turtlegas::turtle::Registry&)`.
#
# It is compiled against the controller API's headers only (turtlegas::controller_sdk) and links no
# turtlegas library: the API's code comes from the turtlegas program that loads it (which exports
# its symbols), so there is one runtime, not two. The flags are the program's where they matter:
#   -fstack-clash-protection  a controller runs on a small stack with a guard page below it
#                             (32 KiB by default, --stack-kib); a frame larger than a page must
#                             touch the guard page on its way down, so that an overflow is a fault
#                             of that turtle and never a silent write past the guard
#   -ffp-contract=off         no fused multiply-adds chosen by the optimiser: a controller's
#                             arithmetic, and so the run, is the same in every build type
# Used by the source tree (controllers/CMakeLists.txt, tests/cli) and installed with the CMake
# package (find_package(turtlegas)), so that both build plugins the same way.
function(turtlegas_add_plugin name)
  if(NOT ARGN)
    message(FATAL_ERROR "turtlegas_add_plugin(${name}): name at least one source file")
  endif()
  add_library(${name} MODULE ${ARGN})
  target_link_libraries(${name} PRIVATE turtlegas::controller_sdk)
  target_compile_options(${name} PRIVATE -fstack-clash-protection -ffp-contract=off)
  set_target_properties(${name} PROPERTIES PREFIX "lib" CXX_EXTENSIONS OFF)
endfunction()
