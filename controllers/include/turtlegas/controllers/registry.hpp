// SPDX-License-Identifier: MIT
#pragma once

#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::controllers {

/// Every built-in controller (and `script`), by the names world files use. An explicit table:
/// see registry.cpp.
turtle::Registry builtin_registry();

}  // namespace turtlegas::controllers
