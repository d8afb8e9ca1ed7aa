// SPDX-License-Identifier: MIT
// Controllers by name: the table world files name them by. A controller (or a plugin's
// turtlegas_register) needs this header and turtle.hpp, nothing else of the runtime.
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::turtle {

/// One parameter a controller reads from its `params`. Declared in the registry, it lets the
/// loader check world files (`check`, `run`, `test`: a typo, a wrong type or a value out of range
/// is an error naming the JSON path), gives the controller its default (Params::get<T>(key)), and
/// is listed by `turtlegas controllers`.
struct ParamSpec {
  enum class Type { number, integer, boolean, string, list };
  std::string name;
  Type type = Type::number;
  nlohmann::json fallback;  ///< the default, used when the key is absent; null: the key is optional, no default
  double min = -std::numeric_limits<double>::infinity();  ///< number and integer: the range, inclusive
  double max = std::numeric_limits<double>::infinity();
  std::vector<std::string> choices;  ///< string: the values allowed (empty: any)
  std::string help;                  ///< one line, with the unit
};

/// A number (a JSON number, not a boolean) from min to max.
ParamSpec number_param(std::string name, double fallback, double min, double max, std::string help);
/// A whole number from min to max (each within +-2^53).
ParamSpec integer_param(std::string name, std::int64_t fallback, std::int64_t min, std::int64_t max, std::string help);
ParamSpec boolean_param(std::string name, bool fallback, std::string help);
/// A string, one of `choices` when any are given.
ParamSpec string_param(std::string name, std::string fallback, std::vector<std::string> choices, std::string help);

/// What the registry knows of a controller besides its code.
struct ControllerInfo {
  std::string summary;  ///< one line
  /// Its parameters; when declared (params_declared, set by the add() that takes an info), a world
  /// file's params must use these keys only (and `x-` ones, which are comments).
  std::vector<ParamSpec> params;
  bool params_declared = false;
  /// The program does the same thing when run again from the start in the same world: it
  /// depends on nothing but its Turtle and Params (no wall clock, no files, no state kept
  /// outside the program), so re-running the world replays it exactly. A checkpoint holds no
  /// program state; `run --resume` replays the run to the checkpoint's time, which needs every
  /// controller of the world to be restartable (docs/controllers.md, "Checkpoints").
  bool restartable = false;
};

/// A problem with a world file's params: the key's JSON pointer below params ("/stpe") and why.
struct ParamProblem {
  std::string pointer;
  std::string reason;
};

/// The first problem of `params` (a JSON object) against `controller`'s declarations, or none
/// (also when it declares none). Keys beginning with "x-" are comments and never a problem.
std::optional<ParamProblem> check_params(const std::string& controller, const ControllerInfo& info,
                                         const nlohmann::json& params);
/// `params` with the declared default of every absent key filled in.
nlohmann::json with_defaults(const ControllerInfo& info, nlohmann::json params);
/// "number 0 to 1e+09", "integer >= 0", "boolean", "right|left": a parameter's type and range.
std::string describe_type(const ParamSpec& spec);

/// Controllers by name. The runtime knows `script`; controllers/ adds the rest.
class Registry {
 public:
  /// A controller that declares no parameters: its params are passed on unchecked.
  void add(std::string name, Controller controller, std::string summary = {});
  /// A controller with its parameters (and whether it is restartable) declared.
  void add(std::string name, Controller controller, ControllerInfo info);
  const Controller* find(const std::string& name) const;
  /// What is declared of `name`, or nullptr when it is not registered.
  const ControllerInfo* info(const std::string& name) const;
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
  std::map<std::string, std::pair<Controller, ControllerInfo>> entries_;
};

/// The built-in `script` controller: runs `params.commands`, a list of [name, amount] pairs
/// (forward, back, left, right, wait; pendown and penup take no amount).
void script_controller(Turtle& t, const Params& p);

/// A registry holding `script` only.
Registry base_registry();

}  // namespace turtlegas::turtle
