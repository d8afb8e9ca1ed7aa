// SPDX-License-Identifier: MIT
// Blindfold tag (AI Memo 272's turtles, playing): one turtle is "it"; when "it" touches another
// turtle, that one becomes "it" — except that the turtle that just gave "it" away cannot be tagged
// back within `no_tag_back` seconds of that tag.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "turtlegas/turtle/game.hpp"

namespace turtlegas::turtle {

/// The rules: the world file's `"game": {"kind": "tag", ...}`.
struct TagRules {
  std::string it;            ///< id of the turtle that starts as "it"
  double no_tag_back = 2.0;  ///< seconds during which the last tagger cannot be tagged back
};

/// Per turtle, in world-file order.
struct TagScore {
  std::vector<std::string> ids;
  std::vector<double> time_it;     ///< seconds spent as "it"
  std::vector<std::size_t> tags;   ///< tags made (passing "it" on)
  std::vector<std::size_t> tagged; ///< times tagged (receiving "it")
  std::string it;                  ///< who is "it" now
  double t = 0.0;                  ///< the time the score is for
};

/// The tag referee. Role changes happen at control-step boundaries: at boundary t the referee
/// looks at the previous step's turtle-turtle contacts in time order, passes "it" on for each
/// contact of the current "it" (so one step can see a chain of tags), logs each tag as
/// {"kind": "tag", "a": tagger, "b": tagged} at t, sends both turtles a "tag" message and moves the
/// time-as-it clock at t. No-tag-back compares the contacts' exact times.
class TagGame final : public Game {
 public:
  /// Throws std::invalid_argument if rules.it names no turtle (checked at start).
  explicit TagGame(TagRules rules) : rules_(std::move(rules)) {}

  void start(double t, GameHost& host) override;
  void referee(double t, std::span<const sim::TurtleContact> contacts, GameHost& host) override;
  /// {"kind": "tag", "t", "it", "turtles": [{"id", "time_it", "tags", "tagged"}]}
  nlohmann::json score(double t) const override;
  /// {"kind": "tag", "no_tag_back": seconds}
  nlohmann::json rules_for_players() const override {
    return {{"kind", "tag"}, {"no_tag_back", rules_.no_tag_back}};
  }

  /// The score at time t; time_it sums to t minus the start time.
  TagScore tally(double t) const;
  const TagRules& rules() const { return rules_; }

 private:
  TagRules rules_;
  std::vector<std::string> ids_;
  std::vector<double> time_it_;
  std::vector<std::size_t> tags_, tagged_;
  std::size_t it_ = 0;
  double since_ = 0.0;                         // when it_ became "it" (a boundary)
  std::size_t last_giver_ = static_cast<std::size_t>(-1);  // who passed "it" to it_, if anyone
  double last_tag_contact_ = 0.0;              // the contact time of that tag
};

}  // namespace turtlegas::turtle
