// SPDX-License-Identifier: MIT
#include "turtlegas/turtle/registry.hpp"

#include <stdexcept>
#include <string>
#include <vector>

#include "turtlegas/sim/suggest.hpp"

#include "mirror_controller.hpp"

namespace turtlegas::turtle {

void Registry::add(std::string name, Controller controller, std::string summary) {
  entries_[std::move(name)] = {std::move(controller), std::move(summary)};
}

const Controller* Registry::find(const std::string& name) const {
  auto it = entries_.find(name);
  return it == entries_.end() ? nullptr : &it->second.first;
}

const Controller& Registry::require(const std::string& name, const std::string& context) const {
  if (const Controller* c = find(name)) return *c;
  throw std::invalid_argument(context.empty() ? not_registered(name) : context + ": " + not_registered(name));
}

std::string Registry::not_registered(const std::string& name) const {
  const std::vector<std::string> known = names();
  return "controller '" + name + "' is not registered; known: " + sim::join_names(known) +
         sim::suggestion(name, known, "'");
}

std::vector<std::string> Registry::names() const {
  std::vector<std::string> out;
  for (const auto& [name, entry] : entries_) out.push_back(name);
  return out;
}

const std::string& Registry::summary(const std::string& name) const {
  static const std::string none;
  auto it = entries_.find(name);
  return it == entries_.end() ? none : it->second.second;
}

Registry base_registry() {
  Registry r;
  r.add("script", script_controller, "runs params.commands, a fixed list of [command, amount]");
  r.add("mirror", detail::mirror_controller,
        "runs another controller as its mirror image (of, params, axis, through, twin: share its random stream)");
  return r;
}

}  // namespace turtlegas::turtle
