// SPDX-License-Identifier: MIT
#include "turtlegas/turtle/tag_game.hpp"

#include <stdexcept>

namespace turtlegas::turtle {

void TagGame::start(double t, GameHost& host) {
  ids_.clear();
  for (std::size_t i = 0; i < host.turtle_count(); ++i) ids_.push_back(host.turtle_id(i));
  std::size_t it = ids_.size();
  for (std::size_t i = 0; i < ids_.size(); ++i)
    if (ids_[i] == rules_.it) it = i;
  if (it == ids_.size()) throw std::invalid_argument("tag: \"it\" names no turtle: '" + rules_.it + "'");
  if (!(rules_.no_tag_back >= 0.0)) throw std::invalid_argument("tag: no_tag_back must be >= 0");
  time_it_.assign(ids_.size(), 0.0);
  tags_.assign(ids_.size(), 0);
  tagged_.assign(ids_.size(), 0);
  it_ = it;
  since_ = t;
  last_giver_ = static_cast<std::size_t>(-1);
  for (std::size_t i = 0; i < ids_.size(); ++i) host.set_it(i, i == it_);
}

void TagGame::referee(double t, std::span<const sim::TurtleContact> contacts, GameHost& host) {
  for (const sim::TurtleContact& c : contacts) {
    // Each turtle-turtle contact comes twice; "it"'s own record names the other turtle.
    if (c.kind != sim::EventKind::turtle_turtle || c.turtle != it_ || c.other == it_) continue;
    const std::size_t other = c.other;
    if (other == last_giver_ && c.t - last_tag_contact_ < rules_.no_tag_back) continue;
    time_it_[it_] += t - since_;
    since_ = t;
    ++tags_[it_];
    ++tagged_[other];
    host.set_it(it_, false);
    host.set_it(other, true);
    host.send(it_, Message{nlohmann::json{{"kind", "tag"}, {"it", false}, {"by", ids_[other]}}, t});
    host.send(other, Message{nlohmann::json{{"kind", "tag"}, {"it", true}, {"by", ids_[it_]}}, t});
    host.log_event(LogEvent{t, "tag", ids_[it_], ids_[other], {}, 0.0, {}, {}, {}});
    last_giver_ = it_;
    last_tag_contact_ = c.t;
    it_ = other;
  }
}

TagScore TagGame::tally(double t) const {
  TagScore s{ids_, time_it_, tags_, tagged_, ids_.empty() ? std::string() : ids_[it_], t};
  if (!ids_.empty()) s.time_it[it_] += t - since_;
  return s;
}

nlohmann::json TagGame::score(double t) const {
  const TagScore s = tally(t);
  nlohmann::json turtles = nlohmann::json::array();
  for (std::size_t i = 0; i < s.ids.size(); ++i)
    turtles.push_back({{"id", s.ids[i]}, {"time_it", s.time_it[i]}, {"tags", s.tags[i]}, {"tagged", s.tagged[i]}});
  return {{"kind", "tag"}, {"t", t}, {"it", s.it}, {"turtles", turtles}};
}

}  // namespace turtlegas::turtle
