// SPDX-License-Identifier: MIT
// Controllers by name: the table world files name them by. A controller (or a plugin's
// turtlegas_register) needs this header and turtle.hpp, nothing else of the runtime.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::turtle {

/// Controllers by name. The runtime knows `script`; controllers/ adds the rest.
class Registry {
 public:
  void add(std::string name, Controller controller, std::string summary = {});
  const Controller* find(const std::string& name) const;
  /// The controller called `name`. Throws std::invalid_argument with not_registered(name), after
  /// `context` and ": " when a context is given ("turtle 't1'", "--controllers").
  const Controller& require(const std::string& name, const std::string& context = {}) const;
  /// What require throws for a name it does not hold: "controller 'wandr' is not registered; known:
  /// script, spiral, ..., wander; did you mean 'wander'?" (every registered name, in order; the
  /// suggestion only for a close misspelling, fewer than 3 edits).
  std::string not_registered(const std::string& name) const;
  std::vector<std::string> names() const;
  const std::string& summary(const std::string& name) const;

 private:
  std::map<std::string, std::pair<Controller, std::string>> entries_;
};

/// The built-in `script` controller: runs `params.commands`, a list of [name, amount] pairs
/// (forward, back, left, right, wait; pendown and penup take no amount).
void script_controller(Turtle& t, const Params& p);

/// A registry holding `script` only.
Registry base_registry();

}  // namespace turtlegas::turtle
