// SPDX-License-Identifier: MIT
// The extension turtlegas._turtlegas; the package's __init__.py re-exports it (docs/python.md).
#include <pybind11/pybind11.h>

#include "programs.hpp"
#include "vec_world_py.hpp"
#include "world.hpp"

PYBIND11_MODULE(_turtlegas, m) {
  m.doc() = "turtlegas in process: worlds, their state as numpy arrays, events and observables (docs/python.md)";
  turtlegas::python::bind_programs(m);
  turtlegas::python::bind_world(m);
  turtlegas::python::bind_vec_world(m);
}
