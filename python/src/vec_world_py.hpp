// SPDX-License-Identifier: MIT
// The module's VecWorld class (vec_world_py.cpp), added to the module by its PYBIND11_MODULE.
#pragma once

#include <pybind11/pybind11.h>

namespace turtlegas::python {

/// Adds turtlegas._VecWorld to m.
void bind_vec_world(pybind11::module_& m);

}  // namespace turtlegas::python
