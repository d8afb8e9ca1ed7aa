// SPDX-License-Identifier: MIT
// Python programs (turtlegas/programs.py, docs/python.md "Python programs"): a turtle's program
// written as a Python generator runs as that turtle's own program in the world server, on its
// coroutine, exactly where a C++ controller would: the registered controller `python` resumes the
// generator, which yields its next command; the controller issues it through the same Turtle API
// and sends the result back as the value of the yield. One interpreter, no thread per turtle.
//
// The world's changes asked for from Python (spawn, remove, teleport, add_wall) wait in the
// ChangeQueue for the next control boundary, where the world server's own world changes
// (world_changes.cpp, the protocol's) make them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/remote.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::python {

namespace py = pybind11;

/// The controller name a Python program runs under (a world file may name it too, when the
/// program is given to World.load).
inline constexpr const char* python_controller = "python";

/// The programs of one world, by turtle id, and the first exception one of them raised.
struct Programs {
  std::map<std::string, py::object> functions;  ///< generator functions; touched with the GIL held
  std::optional<py::error_already_set> error;   ///< World.run raises it once the run is back
};

/// The controller that runs turtle t's Python program (programs.functions[t.id()]).
turtle::Controller python_program(std::shared_ptr<Programs> programs);

/// Changes for the next control boundary (turtle::InputSource::at_boundary); the world has no
/// remote turtles of its own, so next() gives none.
class ChangeQueue : public turtle::InputSource {
 public:
  /// Plain C++: no Python object may be touched without the GIL, and at_boundary runs without.
  using Change = std::function<void(turtle::WorldServer&)>;
  std::vector<Change> changes;
  /// What the world server refused at the boundary (nothing changed for those): World.run raises it.
  std::vector<std::string> refused;

  void at_boundary(turtle::WorldServer& s, std::uint64_t step) override;
  std::optional<turtle::RemoteCommand> next(std::uint64_t, std::size_t) override { return std::nullopt; }
};

/// Adds the program side's types to the module (the handle a program's Turtle reads through).
void bind_programs(py::module_& m);

}  // namespace turtlegas::python
