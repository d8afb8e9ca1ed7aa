// SPDX-License-Identifier: MIT
#include "turtlegas/turtle/registry.hpp"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "turtlegas/sim/format.hpp"
#include "turtlegas/sim/suggest.hpp"

#include "mirror_controller.hpp"

namespace turtlegas::turtle {
namespace {

std::string num(double v) { return sim::format_number(v); }

// RFC 6901: "~" is written "~0" and "/" "~1" in a pointer's token.
std::string pointer_token(const std::string& key) {
  std::string out;
  for (char c : key) out += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
  return out;
}

std::string with_article(const std::string& noun) {
  return (noun.empty() || std::string("aeiou").find(noun[0]) == std::string::npos ? "a " : "an ") + noun;
}

bool is_comment(const std::string& key) { return key.rfind("x-", 0) == 0; }

std::string kind_of(const nlohmann::json& v) {
  switch (v.type()) {
    case nlohmann::json::value_t::null: return "null";
    case nlohmann::json::value_t::boolean:
    case nlohmann::json::value_t::string: return v.dump();
    case nlohmann::json::value_t::array: return "a list";
    case nlohmann::json::value_t::object: return "an object";
    default: return v.dump();
  }
}

std::string range_words(const ParamSpec& s) {
  const bool lo = std::isfinite(s.min), hi = std::isfinite(s.max);
  if (lo && hi) return " from " + num(s.min) + " to " + num(s.max);
  if (lo) return " >= " + num(s.min);
  if (hi) return " <= " + num(s.max);
  return {};
}

}  // namespace

ParamSpec number_param(std::string name, double fallback, double min, double max, std::string help) {
  return {std::move(name), ParamSpec::Type::number, fallback, min, max, {}, std::move(help)};
}

ParamSpec integer_param(std::string name, std::int64_t fallback, std::int64_t min, std::int64_t max, std::string help) {
  return {std::move(name), ParamSpec::Type::integer, fallback, static_cast<double>(min), static_cast<double>(max), {},
          std::move(help)};
}

ParamSpec boolean_param(std::string name, bool fallback, std::string help) {
  return {std::move(name), ParamSpec::Type::boolean, fallback, -INFINITY, INFINITY, {}, std::move(help)};
}

ParamSpec string_param(std::string name, std::string fallback, std::vector<std::string> choices, std::string help) {
  return {std::move(name), ParamSpec::Type::string, std::move(fallback), -INFINITY, INFINITY, std::move(choices),
          std::move(help)};
}

std::string describe_type(const ParamSpec& s) {
  switch (s.type) {
    case ParamSpec::Type::number: return "number" + range_words(s);
    case ParamSpec::Type::integer: return "integer" + range_words(s);
    case ParamSpec::Type::boolean: return "boolean";
    case ParamSpec::Type::string: {
      if (s.choices.empty()) return "string";
      std::string c;
      for (const std::string& choice : s.choices) c += (c.empty() ? "" : "|") + choice;
      return "string (" + c + ")";
    }
    case ParamSpec::Type::list: return "list";
  }
  return "?";
}

std::optional<ParamProblem> check_params(const std::string& controller, const ControllerInfo& info,
                                         const nlohmann::json& params) {
  if (!info.params_declared || !params.is_object()) return std::nullopt;
  std::vector<std::string> known;
  for (const ParamSpec& s : info.params) known.push_back(s.name);
  for (const auto& item : params.items()) {
    // Named, not a structured binding: clang 14 cannot capture those in the lambda below.
    const std::string& key = item.key();
    const nlohmann::json& value = item.value();
    if (is_comment(key)) continue;
    const std::string pointer = "/" + pointer_token(key);
    const ParamSpec* spec = nullptr;
    for (const ParamSpec& s : info.params)
      if (s.name == key) spec = &s;
    if (!spec) {
      std::string reason = "unknown key \"" + key + "\" in the " + controller + " controller's params; ";
      reason += known.empty() ? std::string("it takes none") : "known: " + sim::join_names(known);
      return ParamProblem{pointer, reason + sim::suggestion(key, known)};
    }
    const std::string want = describe_type(*spec);
    const auto wrong = [&] { return ParamProblem{pointer, key + " must be " + with_article(want) + ", got " + kind_of(value)}; };
    switch (spec->type) {
      case ParamSpec::Type::number:
      case ParamSpec::Type::integer: {
        if (!value.is_number()) return wrong();
        const double v = value.get<double>();
        // An integer written as 1e3 is an integer; 2.5 is not. Integers beyond 2^53 are refused
        // by the range (ranges stay within +-2^53, where a double holds every integer).
        const bool whole = spec->type == ParamSpec::Type::number || std::trunc(v) == v;
        if (!whole || !(v >= spec->min && v <= spec->max)) return wrong();
        break;
      }
      case ParamSpec::Type::boolean:
        if (!value.is_boolean()) return wrong();
        break;
      case ParamSpec::Type::string: {
        if (!value.is_string()) return wrong();
        const std::string v = value.get<std::string>();
        if (!spec->choices.empty()) {
          bool found = false;
          for (const std::string& c : spec->choices) found = found || c == v;
          if (!found)
            return ParamProblem{pointer, key + " must be one of " + sim::join_names(spec->choices, "\"") + ", got \"" +
                                             v + "\"" + sim::suggestion(v, spec->choices)};
        }
        break;
      }
      case ParamSpec::Type::list:
        if (!value.is_array()) return wrong();
        break;
    }
  }
  return std::nullopt;
}

nlohmann::json with_defaults(const ControllerInfo& info, nlohmann::json params) {
  if (!params.is_object()) return params;
  for (const ParamSpec& s : info.params)
    if (!s.fallback.is_null() && !params.contains(s.name)) params[s.name] = s.fallback;
  return params;
}

void Registry::add(std::string name, Controller controller, std::string summary) {
  ControllerInfo info;
  info.summary = std::move(summary);
  entries_[std::move(name)] = {std::move(controller), std::move(info)};
}

void Registry::add(std::string name, Controller controller, ControllerInfo info) {
  info.params_declared = true;
  entries_[std::move(name)] = {std::move(controller), std::move(info)};
}

const Controller* Registry::find(const std::string& name) const {
  auto it = entries_.find(name);
  return it == entries_.end() ? nullptr : &it->second.first;
}

const ControllerInfo* Registry::info(const std::string& name) const {
  auto it = entries_.find(name);
  return it == entries_.end() ? nullptr : &it->second.second;
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
  return it == entries_.end() ? none : it->second.second.summary;
}

Registry base_registry() {
  Registry r;
  ControllerInfo script;
  script.summary = "runs params.commands, a fixed list of [command, amount]";
  script.params.push_back({"commands", ParamSpec::Type::list, nullptr, -INFINITY, INFINITY, {},
                           "[[\"forward\", 100], [\"right\", 90], ...]: forward, back (units), left, right (degrees), "
                           "wait (seconds), pendown, penup, [\"sense\", NAME], [\"camera\", NAME], [\"arc\", radius, degrees], "
                           "[\"drive\", v, omega, seconds], [\"wheels\", left, right, seconds]"});
  // A script's place is its command index and the time: re-running it from the start replays it.
  script.restartable = true;
  r.add("script", script_controller, std::move(script));
  r.add("mirror", detail::mirror_controller,
        "runs another controller as its mirror image (of, params, axis, through, twin: share its random stream)");
  return r;
}

}  // namespace turtlegas::turtle
