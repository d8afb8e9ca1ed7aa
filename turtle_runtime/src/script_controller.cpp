// SPDX-License-Identifier: MIT
// The built-in `script` controller: a world file's fixed list of commands (script.hpp's table; the
// loader checks a script against the same table before the run, so these errors are for scripts
// that did not come through it).
#include <cstddef>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/suggest.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/script.hpp"
#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::turtle {

void script_controller(Turtle& t, const Params& p) {
  using Op = ScriptCommand::Op;
  const nlohmann::json& commands = p.json().contains("commands") ? p.json().at("commands") : nlohmann::json::array();
  if (!commands.is_array()) throw std::invalid_argument("params.commands must be a list of [command, amount]");
  std::vector<Reading> readings;
  for (std::size_t k = 0; k < commands.size(); ++k) {
    const nlohmann::json& c = commands[k];
    const std::string where = "params.commands[" + std::to_string(k) + "]";
    if (!c.is_array() || c.empty() || !c[0].is_string())
      throw std::invalid_argument(where + " must be [command, amount], e.g. [\"forward\", 100]");
    const std::string name = c[0].get<std::string>();
    const ScriptCommand* command = find_script_command(name);
    const Op op = command ? command->op : Op::forward;
    if (command && op == Op::pendown && c.size() == 2 && c[1].is_string()) {
      const std::string mode = c[1].get<std::string>();
      if (mode != "wall" && mode != "line")
        throw std::invalid_argument(where + ": a pen mode is \"line\" or \"wall\", got \"" + mode + "\"");
      t.pen_down(mode == "wall" ? PenMode::wall : PenMode::line);
      continue;
    }
    if (command && op == Op::pendown) { t.pen_down(); continue; }
    if (command && op == Op::penup) { t.pen_up(); continue; }
    if (command && (op == Op::sense || op == Op::camera)) {
      if (c.size() != 2 || !c[1].is_string())
        throw std::invalid_argument(where + ": '" + name + "' needs a sensor's name, e.g. [\"" + name + "\", \"" +
                                    (op == Op::sense ? "front" : "cam") + "\"]");
      // Both logged as a `sense` event (a camera's with its colours).
      if (op == Op::sense) t.scan(c[1].get<std::string>(), readings);
      else t.camera(c[1].get<std::string>(), readings);
      continue;
    }
    if (command && command->steers()) {
      bool numbers = c.size() == 1 + command->numbers();
      for (std::size_t j = 1; numbers && j < c.size(); ++j) numbers = c[j].is_number();
      if (!numbers)
        throw std::invalid_argument(where + ": '" + name + "' needs " + std::to_string(command->numbers()) +
                                    " numbers, e.g. " + std::string(command->example()));
      const double x = c[1].get<double>(), y = c[2].get<double>();
      if (op == Op::arc) t.arc(x, y);
      else if (op == Op::drive) t.drive(x, y, c[3].get<double>());
      else t.wheels(x, y, c[3].get<double>());
      continue;
    }
    if (c.size() != 2 || !c[1].is_number())
      throw std::invalid_argument(where + ": '" + name + "' needs one number, e.g. [\"" + name + "\", 100]");
    if (!command) {
      throw std::invalid_argument(where + ": unknown command '" + name +
                                  "'; known: " + sim::join_names(script_command_names()));
    }
    const double amount = c[1].get<double>();
    switch (op) {
      case Op::forward: t.forward(amount); break;
      case Op::back: t.back(amount); break;
      case Op::left: t.left(amount); break;
      case Op::right: t.right(amount); break;
      case Op::wait: t.wait(amount); break;
      case Op::pendown:
      case Op::penup:
      case Op::sense:
      case Op::camera:
      case Op::arc:
      case Op::drive:
      case Op::wheels: break;  // handled above
    }
  }
}

}  // namespace turtlegas::turtle
