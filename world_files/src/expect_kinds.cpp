// SPDX-License-Identifier: MIT
// The assertion kinds of `expect` lists: one class per kind (what it checks during a run, and
// what it says when it fails), its parser, and the explicit table of kinds (assertion_kinds()). A
// new kind is one class, one parse function and one line of the table.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "turtlegas/sim/format.hpp"
#include "turtlegas/turtle/colours.hpp"
#include "turtlegas/turtle/game.hpp"
#include "turtlegas/world/expect.hpp"
#include "turtlegas/world/json_read.hpp"
#include "turtlegas/world/run_view.hpp"

namespace turtlegas::world {
namespace {

using json = nlohmann::json;
using sim::Vec2;

std::string num(double v) { return sim::format_number(v); }
std::string vec(Vec2 v) { return sim::format_vec(v); }

// JSON pointers (RFC 6901), as the loader writes them.
std::string at(const std::string& path, std::string_view key) { return json_at(path, key); }
std::string at(const std::string& path, std::size_t index) { return json_at(path, index); }

// ---- event filters: {"event"|"no_event"|"count": KIND, "a": id, "b": id, "after": t, "before": t}

struct EventFilter {
  std::string kind;
  std::string a, b;  // empty: any
  double after = -std::numeric_limits<double>::infinity();
  double before = std::numeric_limits<double>::infinity();

  bool matches_bodies(const turtle::LogEvent& e) const {
    return e.kind == kind && (a.empty() || e.a == a) && (b.empty() || e.b == b);
  }
  bool in_window(double t) const { return t >= after && t < before; }

  static EventFilter parse(const json& entry, const std::string& path, std::string_view key, const ExpectParser& p) {
    EventFilter f;
    f.kind = p.event_kind(entry.at(std::string(key)), at(path, key));
    if (auto it = entry.find("a"); it != entry.end()) f.a = p.body_id(*it, at(path, "a"));
    if (auto it = entry.find("b"); it != entry.end()) f.b = p.body_id(*it, at(path, "b"));
    if (auto it = entry.find("after"); it != entry.end()) f.after = p.non_negative(*it, at(path, "after"));
    if (auto it = entry.find("before"); it != entry.end()) f.before = p.non_negative(*it, at(path, "before"));
    if (!(f.after < f.before)) p.fail(path, "\"after\" (" + num(f.after) + ") must be less than \"before\" (" + num(f.before) + ")");
    return f;
  }

  /// "touch (a t1, b w3) before t = 5"
  std::string describe() const {
    std::string s = kind;
    if (!a.empty() || !b.empty()) {
      s += " (";
      if (!a.empty()) s += "a " + a;
      if (!b.empty()) s += (a.empty() ? "b " : ", b ") + b;
      s += ")";
    }
    if (std::isfinite(after)) s += " after t = " + num(after);
    if (std::isfinite(before)) s += (std::isfinite(after) ? " and" : "") + std::string(" before t = ") + num(before);
    return s;
  }
};

std::string describe_event(const turtle::LogEvent& e) {
  std::string s = "t = " + num(e.t) + " (" + e.a;
  if (!e.b.empty()) s += " with " + e.b;
  return s + ")";
}

/// {"event": KIND, ...}: at least one matching event in the window.
class EventAssertion final : public Assertion {
 public:
  explicit EventAssertion(EventFilter f) : f_(std::move(f)) {}
  std::unique_ptr<Check> start(const RunView&) const override {
    struct C final : Check {
      const EventFilter& f;
      bool seen = false;
      std::optional<turtle::LogEvent> outside;  // first match of the bodies outside the window
      explicit C(const EventFilter& f_) : f(f_) {}
      void on_event(const turtle::LogEvent& e, const RunView&) override {
        if (seen || !f.matches_bodies(e)) return;
        if (f.in_window(e.t)) seen = true;
        else if (!outside) outside = e;
      }
      std::optional<std::string> finish(const RunView& v) override {
        if (seen) return std::nullopt;
        std::string m = "event " + f.describe() + ": none happened";
        if (outside) m += " (the first such event is at " + describe_event(*outside) + ")";
        else m += " by t = " + num(v.time());
        return m;
      }
    };
    return std::make_unique<C>(f_);
  }

 private:
  EventFilter f_;
};

/// {"no_event": KIND, ...}: no matching event in the window.
class NoEventAssertion final : public Assertion {
 public:
  explicit NoEventAssertion(EventFilter f) : f_(std::move(f)) {}
  std::unique_ptr<Check> start(const RunView&) const override {
    struct C final : Check {
      const EventFilter& f;
      std::optional<turtle::LogEvent> first;
      std::size_t n = 0;
      explicit C(const EventFilter& f_) : f(f_) {}
      void on_event(const turtle::LogEvent& e, const RunView&) override {
        if (!f.matches_bodies(e) || !f.in_window(e.t)) return;
        if (!first) first = e;
        ++n;
      }
      std::optional<std::string> finish(const RunView&) override {
        if (!first) return std::nullopt;
        std::string m = "no_event " + f.describe() + ": " + std::to_string(n) + " happened, the first at " +
                        describe_event(*first);
        if (!first->message.empty()) m += ": " + first->message;
        return m;
      }
    };
    return std::make_unique<C>(f_);
  }

 private:
  EventFilter f_;
};

/// {"count": KIND, "min": n, "max": n, ...}: the number of matching events is within bounds.
class CountAssertion final : public Assertion {
 public:
  CountAssertion(EventFilter f, std::optional<double> min, std::optional<double> max)
      : f_(std::move(f)), min_(min), max_(max) {}
  std::unique_ptr<Check> start(const RunView&) const override {
    struct C final : Check {
      const CountAssertion& self;
      std::uint64_t n = 0;
      explicit C(const CountAssertion& s) : self(s) {}
      void on_event(const turtle::LogEvent& e, const RunView&) override {
        n += self.f_.matches_bodies(e) && self.f_.in_window(e.t) ? 1 : 0;
      }
      std::optional<std::string> finish(const RunView&) override {
        const double x = static_cast<double>(n);
        const std::string head = "count " + self.f_.describe() + " = " + std::to_string(n) + ", wanted ";
        if (self.min_ && x < *self.min_) return head + ">= " + num(*self.min_);
        if (self.max_ && x > *self.max_) return head + "<= " + num(*self.max_);
        return std::nullopt;
      }
    };
    return std::make_unique<C>(*this);
  }

 private:
  EventFilter f_;
  std::optional<double> min_, max_;
};

std::shared_ptr<const Assertion> parse_event(const json& e, const std::string& path, const ExpectParser& p) {
  p.check_keys(e, path, "event", {"a", "b", "after", "before"});
  return std::make_shared<EventAssertion>(EventFilter::parse(e, path, "event", p));
}

std::shared_ptr<const Assertion> parse_no_event(const json& e, const std::string& path, const ExpectParser& p) {
  p.check_keys(e, path, "no_event", {"a", "b", "after", "before"});
  return std::make_shared<NoEventAssertion>(EventFilter::parse(e, path, "no_event", p));
}

std::shared_ptr<const Assertion> parse_count(const json& e, const std::string& path, const ExpectParser& p) {
  p.check_keys(e, path, "count", {"a", "b", "after", "before", "min", "max"});
  std::optional<double> min, max;
  if (auto it = e.find("min"); it != e.end()) min = p.non_negative(*it, at(path, "min"));
  if (auto it = e.find("max"); it != e.end()) max = p.non_negative(*it, at(path, "max"));
  if (!min && !max) p.fail(path, "count needs \"min\", \"max\" or both, e.g. {\"count\": \"ball-wall\", \"min\": 10}");
  if (min && max && *min > *max) p.fail(at(path, "min"), "min (" + num(*min) + ") is more than max (" + num(*max) + ")");
  return std::make_shared<CountAssertion>(EventFilter::parse(e, path, "count", p), min, max);
}

// ---- {"inside": [[x0, y0], [x1, y1]], "who": ids or "*"}: centres stay in the region at every step

class InsideAssertion final : public Assertion {
 public:
  InsideAssertion(Vec2 lo, Vec2 hi, std::vector<std::string> who) : lo_(lo), hi_(hi), who_(std::move(who)) {}
  std::unique_ptr<Check> start(const RunView&) const override {
    struct C final : Check {
      const InsideAssertion& self;
      std::optional<std::string> failure;
      explicit C(const InsideAssertion& s) : self(s) {}
      void test(const std::string& id, Vec2 pos, double t) {
        if (failure) return;
        if (pos.x >= self.lo_.x && pos.x <= self.hi_.x && pos.y >= self.lo_.y && pos.y <= self.hi_.y) return;
        failure = "inside [" + vec(self.lo_) + ", " + vec(self.hi_) + "]: " + id + " is at " + vec(pos) +
                  " at t = " + num(t);
      }
      void on_step(const RunView& v) override {
        if (failure) return;
        if (self.who_.empty()) {
          v.for_each_body([&](const std::string& id, Vec2 pos) { test(id, pos, v.time()); });
          return;
        }
        for (const std::string& id : self.who_) {
          const RunView::Body b = v.body(id);
          if (b.alive) test(id, b.pos, v.time());
          else if (!failure) failure = "inside: " + id + " has left the arena by t = " + num(v.time());
        }
      }
      std::optional<std::string> finish(const RunView&) override { return failure; }
    };
    return std::make_unique<C>(*this);
  }

 private:
  Vec2 lo_, hi_;
  std::vector<std::string> who_;
};

std::shared_ptr<const Assertion> parse_inside(const json& e, const std::string& path, const ExpectParser& p) {
  p.check_keys(e, path, "inside", {"who"});
  const json& r = e.at("inside");
  const std::string rp = at(path, "inside");
  if (!r.is_array() || r.size() != 2) p.fail(rp, "expected [[x0, y0], [x1, y1]] (two corners), got " + r.dump());
  const Vec2 lo = p.vec2(r[0], at(rp, 0)), hi = p.vec2(r[1], at(rp, 1));
  if (!(lo.x <= hi.x && lo.y <= hi.y)) p.fail(rp, "give the lower-left corner first: x0 <= x1 and y0 <= y1");
  std::vector<std::string> who;
  if (auto it = e.find("who"); it != e.end()) who = p.who(*it, at(path, "who"));
  return std::make_shared<InsideAssertion>(lo, hi, std::move(who));
}

// ---- checks of one body at one time: near, heading, speed. "at": "end" (default) or a time.

/// A check of one body sampled at the end or at a given time.
class SampledAssertion : public Assertion {
 public:
  SampledAssertion(std::string who, std::optional<double> when) : who_(std::move(who)), at_(when) {}
  std::vector<double> sample_times() const override {
    return at_ ? std::vector<double>{*at_} : std::vector<double>{};
  }
  std::unique_ptr<Check> start(const RunView&) const override {
    struct C final : Check {
      const SampledAssertion& self;
      std::optional<std::string> result;
      bool sampled = false;
      explicit C(const SampledAssertion& s) : self(s) {}
      void on_step(const RunView& v) override {
        if (sampled || !self.at_ || v.time() != *self.at_) return;
        sampled = true;
        result = self.test(v.body(self.who_), v.time());
      }
      std::optional<std::string> finish(const RunView& v) override {
        if (!self.at_) return self.test(v.body(self.who_), v.time());
        if (!sampled) return self.name() + " " + self.who_ + ": the run ended at t = " + num(v.time()) +
                             " before t = " + num(*self.at_);
        return result;
      }
    };
    return std::make_unique<C>(*this);
  }

 protected:
  virtual std::string name() const = 0;
  /// The failure, or nullopt.
  virtual std::optional<std::string> test(const RunView::Body& b, double t) const = 0;
  std::string who_;
  std::optional<double> at_;
};

class NearAssertion final : public SampledAssertion {
 public:
  NearAssertion(std::string who, std::optional<double> when, Vec2 point, double within)
      : SampledAssertion(std::move(who), when), point_(point), within_(within) {}

 private:
  std::string name() const override { return "near " + vec(point_); }
  std::optional<std::string> test(const RunView::Body& b, double t) const override {
    const double d = std::hypot(b.pos.x - point_.x, b.pos.y - point_.y);
    if (b.alive && d <= within_) return std::nullopt;
    if (!b.alive) return name() + ": " + who_ + " has left the arena by t = " + num(t);
    return name() + ": " + who_ + " is at " + vec(b.pos) + " at t = " + num(t) + ", distance " + num(d) +
           ", wanted <= " + num(within_);
  }
  Vec2 point_;
  double within_;
};

class HeadingAssertion final : public SampledAssertion {
 public:
  HeadingAssertion(std::string who, std::optional<double> when, double heading, double within)
      : SampledAssertion(std::move(who), when), heading_(heading), within_(within) {}

 private:
  std::string name() const override { return "heading " + num(heading_); }
  std::optional<std::string> test(const RunView::Body& b, double t) const override {
    double d = std::fmod(std::abs(b.heading - heading_), 360.0);
    d = std::min(d, 360.0 - d);
    if (d <= within_) return std::nullopt;
    return name() + ": " + who_ + " heads " + num(b.heading) + " degrees at t = " + num(t) + ", off by " + num(d) +
           ", wanted <= " + num(within_);
  }
  double heading_;
  double within_;
};

class SpeedAssertion final : public SampledAssertion {
 public:
  SpeedAssertion(std::string who, std::optional<double> when, std::optional<double> min, std::optional<double> max)
      : SampledAssertion(std::move(who), when), min_(min), max_(max) {}

 private:
  std::string name() const override { return "speed"; }
  std::optional<std::string> test(const RunView::Body& b, double t) const override {
    const double s = std::hypot(b.vel.x, b.vel.y);
    const std::string head = "speed " + who_ + " = " + num(s) + " at t = " + num(t) + ", wanted ";
    if (min_ && !(s >= *min_)) return head + ">= " + num(*min_);
    if (max_ && !(s <= *max_)) return head + "<= " + num(*max_);
    return std::nullopt;
  }
  std::optional<double> min_, max_;
};

std::optional<double> parse_at(const json& e, const std::string& path, const ExpectParser& p) {
  if (auto it = e.find("at"); it != e.end()) return p.at_time(*it, at(path, "at"));
  return std::nullopt;
}

const json& required(const json& e, const std::string& path, std::string_view key, std::string_view kind,
                     const ExpectParser& p) {
  auto it = e.find(key);
  if (it == e.end()) p.fail(path, std::string(kind) + " needs \"" + std::string(key) + "\"");
  return *it;
}

std::shared_ptr<const Assertion> parse_near(const json& e, const std::string& path, const ExpectParser& p) {
  p.check_keys(e, path, "near", {"who", "within", "at"});
  const Vec2 point = p.vec2(e.at("near"), at(path, "near"));
  std::string who = p.body_id(required(e, path, "who", "near", p), at(path, "who"));
  const double within = p.non_negative(required(e, path, "within", "near", p), at(path, "within"));
  return std::make_shared<NearAssertion>(std::move(who), parse_at(e, path, p), point, within);
}

std::shared_ptr<const Assertion> parse_heading(const json& e, const std::string& path, const ExpectParser& p) {
  p.check_keys(e, path, "heading", {"who", "within", "at"});
  const double heading = p.number(e.at("heading"), at(path, "heading"));
  std::string who = p.turtle_id(required(e, path, "who", "heading", p), at(path, "who"));
  double within = 1e-9;
  if (auto it = e.find("within"); it != e.end()) within = p.non_negative(*it, at(path, "within"));
  return std::make_shared<HeadingAssertion>(std::move(who), parse_at(e, path, p), heading, within);
}

std::shared_ptr<const Assertion> parse_speed(const json& e, const std::string& path, const ExpectParser& p) {
  p.check_keys(e, path, "speed", {"min", "max", "at"});
  std::string who = p.body_id(e.at("speed"), at(path, "speed"));
  std::optional<double> min, max;
  if (auto it = e.find("min"); it != e.end()) min = p.non_negative(*it, at(path, "min"));
  if (auto it = e.find("max"); it != e.end()) max = p.non_negative(*it, at(path, "max"));
  if (!min && !max) p.fail(path, "speed needs \"min\", \"max\" or both, e.g. {\"speed\": \"b1\", \"max\": 1e-9}");
  return std::make_shared<SpeedAssertion>(std::move(who), parse_at(e, path, p), min, max);
}

// ---- {"energy": "conserved", "tolerance": rel}: |E(t) - E(0)| <= tol |E(0)| at every step

class EnergyAssertion final : public Assertion {
 public:
  explicit EnergyAssertion(double tolerance) : tolerance_(tolerance) {}
  std::unique_ptr<Check> start(const RunView& v) const override {
    struct C final : Check {
      double tolerance, e0, worst = 0.0, worst_t = 0.0, worst_e = 0.0;
      C(double tol, double e) : tolerance(tol), e0(e), worst_e(e) {}
      void on_step(const RunView& v) override {
        const double e = v.world().energy();
        const double rel = e0 != 0.0 ? std::abs(e - e0) / std::abs(e0) : std::abs(e - e0);
        if (rel > worst) worst = rel, worst_t = v.time(), worst_e = e;
      }
      std::optional<std::string> finish(const RunView& v) override {
        on_step(v);
        if (worst <= tolerance) return std::nullopt;
        return "energy conserved: " + num(e0) + " at t = 0, " + num(worst_e) + " at t = " + num(worst_t) +
               " (relative change " + num(worst) + "), wanted <= " + num(tolerance);
      }
    };
    return std::make_unique<C>(tolerance_, v.world().energy());
  }

 private:
  double tolerance_;
};

std::shared_ptr<const Assertion> parse_energy(const json& e, const std::string& path, const ExpectParser& p) {
  p.check_keys(e, path, "energy", {"tolerance"});
  const std::string what = p.string(e.at("energy"), at(path, "energy"));
  if (what != "conserved") p.fail(at(path, "energy"), "energy must be \"conserved\" (got \"" + what + "\")");
  const double tol = p.non_negative(required(e, path, "tolerance", "energy", p), at(path, "tolerance"));
  return std::make_shared<EnergyAssertion>(tol);
}

// ---- {"max_overlap": f}: no two bodies (or a body and a wall) overlap by more than f of a radius

class OverlapAssertion final : public Assertion {
 public:
  explicit OverlapAssertion(double limit) : limit_(limit) {}
  std::unique_ptr<Check> start(const RunView&) const override {
    struct C final : Check {
      double limit, worst = 0.0, worst_depth = 0.0, worst_t = 0.0;
      explicit C(double l) : limit(l) {}
      void on_step(const RunView& v) override {
        const sim::Overlap o = v.world().measure_overlap();
        if (o.relative > worst) worst = o.relative, worst_depth = o.depth, worst_t = v.time();
      }
      std::optional<std::string> finish(const RunView& v) override {
        on_step(v);
        const sim::Overlap seen = v.world().max_contact_overlap();
        if (seen.relative > worst) worst = seen.relative, worst_depth = seen.depth, worst_t = -1.0;
        if (worst <= limit) return std::nullopt;
        return "max_overlap: " + num(worst) + " of a radius (depth " + num(worst_depth) + ")" +
               (worst_t >= 0.0 ? " at t = " + num(worst_t) : std::string(" at a contact")) + ", wanted <= " + num(limit);
      }
    };
    return std::make_unique<C>(limit_);
  }

 private:
  double limit_;
};

std::shared_ptr<const Assertion> parse_max_overlap(const json& e, const std::string& path, const ExpectParser& p) {
  p.check_keys(e, path, "max_overlap", {});
  return std::make_shared<OverlapAssertion>(p.non_negative(e.at("max_overlap"), at(path, "max_overlap")));
}

// ---- {"it": id, "at": "end"|t}: the game's "it" (the tag game's score names it)

class ItAssertion final : public Assertion {
 public:
  ItAssertion(std::string who, std::optional<double> when) : who_(std::move(who)), at_(when) {}
  std::vector<double> sample_times() const override { return at_ ? std::vector<double>{*at_} : std::vector<double>{}; }
  std::unique_ptr<Check> start(const RunView&) const override {
    struct C final : Check {
      const ItAssertion& self;
      std::optional<std::string> result;
      bool sampled = false;
      explicit C(const ItAssertion& s) : self(s) {}
      void on_step(const RunView& v) override {
        if (sampled || !self.at_ || v.time() != *self.at_) return;
        sampled = true;
        result = self.test(v);
      }
      std::optional<std::string> finish(const RunView& v) override {
        if (!self.at_) return self.test(v);
        if (!sampled) return "it " + self.who_ + ": the run ended at t = " + num(v.time()) + " before t = " + num(*self.at_);
        return result;
      }
    };
    return std::make_unique<C>(*this);
  }

 private:
  std::optional<std::string> test(const RunView& v) const {
    const turtle::Game* game = v.server().game();
    if (!game) return "it " + who_ + ": the world plays no game";
    const json score = game->score(v.time());
    const std::string it = score.is_object() ? score.value("it", std::string()) : std::string();
    if (it == who_) return std::nullopt;
    return "it " + who_ + ": \"it\" is " + (it.empty() ? std::string("nobody") : it) + " at t = " + num(v.time());
  }
  std::string who_;
  std::optional<double> at_;
};

std::shared_ptr<const Assertion> parse_it(const json& e, const std::string& path, const ExpectParser& p) {
  p.check_keys(e, path, "it", {"at"});
  std::string who = p.turtle_id(e.at("it"), at(path, "it"));
  return std::make_shared<ItAssertion>(std::move(who), parse_at(e, path, p));
}

// ---- walls in the world at the end: {"walls": N} (or min/max), {"wall": id, "exists": bool}

class WallsAssertion final : public Assertion {
 public:
  WallsAssertion(std::optional<std::size_t> min, std::optional<std::size_t> max, std::string drawn_by)
      : min_(min), max_(max), drawn_by_(std::move(drawn_by)) {}
  std::unique_ptr<Check> start(const RunView&) const override {
    struct C final : Check {
      const WallsAssertion& self;
      explicit C(const WallsAssertion& s) : self(s) {}
      std::optional<std::string> finish(const RunView& v) override {
        std::size_t n = 0;
        const std::string head = self.drawn_by_ + "-w";
        for (const auto& w : v.world().walls())
          if (self.drawn_by_.empty() || w.id.starts_with(head)) ++n;
        if ((!self.min_ || n >= *self.min_) && (!self.max_ || n <= *self.max_)) return std::nullopt;
        std::string wanted = self.min_ && self.max_ && *self.min_ == *self.max_ ? "= " + std::to_string(*self.min_)
                             : self.min_ && n < *self.min_                     ? ">= " + std::to_string(*self.min_)
                                                                                : "<= " + std::to_string(*self.max_);
        return "walls" + (self.drawn_by_.empty() ? std::string() : " drawn by " + self.drawn_by_) + " = " +
               std::to_string(n) + " at t = " + num(v.time()) + ", wanted " + wanted;
      }
    };
    return std::make_unique<C>(*this);
  }

 private:
  std::optional<std::size_t> min_, max_;
  std::string drawn_by_;
};

std::size_t whole(const json& v, const std::string& path, const ExpectParser& p) {
  const double d = p.non_negative(v, path);
  if (std::floor(d) != d || d > 1e15) p.fail(path, "expected a whole number >= 0, got " + num(d));
  return static_cast<std::size_t>(d);
}

std::shared_ptr<const Assertion> parse_walls(const json& e, const std::string& path, const ExpectParser& p) {
  p.check_keys(e, path, "walls", {"min", "max", "drawn_by"});
  std::optional<std::size_t> min, max;
  const json& n = e.at("walls");
  if (n.is_string() && n == "*") {
    if (auto it = e.find("min"); it != e.end()) min = whole(*it, at(path, "min"), p);
    if (auto it = e.find("max"); it != e.end()) max = whole(*it, at(path, "max"), p);
    if (!min && !max) p.fail(path, "{\"walls\": \"*\"} needs \"min\", \"max\" or both");
  } else {
    if (e.contains("min") || e.contains("max"))
      p.fail(path, "give either a count ({\"walls\": 4}) or bounds ({\"walls\": \"*\", \"min\": 1}), not both");
    min = max = whole(n, at(path, "walls"), p);
  }
  std::string by;
  if (auto it = e.find("drawn_by"); it != e.end()) by = p.turtle_id(*it, at(path, "drawn_by"));
  return std::make_shared<WallsAssertion>(min, max, std::move(by));
}

class WallExistsAssertion final : public Assertion {
 public:
  WallExistsAssertion(std::string id, bool exists) : id_(std::move(id)), exists_(exists) {}
  std::unique_ptr<Check> start(const RunView&) const override {
    struct C final : Check {
      const WallExistsAssertion& self;
      explicit C(const WallExistsAssertion& s) : self(s) {}
      std::optional<std::string> finish(const RunView& v) override {
        const auto& walls = v.world().walls();
        const auto it = std::find_if(walls.begin(), walls.end(), [&](const sim::WallDef& w) { return w.id == self.id_; });
        const bool found = it != walls.end();
        if (found == self.exists_) return std::nullopt;
        if (!found) return "wall " + self.id_ + ": no such wall at t = " + num(v.time());
        return "wall " + self.id_ + ": exists at t = " + num(v.time()) + " (from " + vec(it->from) + " to " +
               vec(it->to) + "), wanted none";
      }
    };
    return std::make_unique<C>(*this);
  }

 private:
  std::string id_;
  bool exists_;
};

std::shared_ptr<const Assertion> parse_wall(const json& e, const std::string& path, const ExpectParser& p) {
  p.check_keys(e, path, "wall", {"exists"});
  std::string id = p.string(e.at("wall"), at(path, "wall"));
  if (id.empty()) p.fail(at(path, "wall"), "a wall id must not be empty");
  bool exists = true;
  if (auto it = e.find("exists"); it != e.end()) {
    exists = p.boolean(*it, at(path, "exists"));
  }
  return std::make_shared<WallExistsAssertion>(std::move(id), exists);
}

// ---- range sensors: {"sense": NAME, "who": turtle, "reading": n, "range": [...], "hit": [...],
// "colour": [...]} (colour: a camera's) or {"sense": NAME, "who": turtle, "min": d, "max": d}

class SenseAssertion final : public Assertion {
 public:
  struct Spec {
    std::string sensor, who;
    std::size_t reading = 0;
    std::optional<json> range, hit;  // lists, an entry per ray (null: nothing within range)
    std::optional<json> colour;      // a camera's: "#rrggbb" per pixel
    double within = 1e-9;
    std::optional<double> min, max;
  };
  explicit SenseAssertion(Spec s) : s_(std::move(s)) {}
  std::unique_ptr<Check> start(const RunView&) const override {
    struct C final : Check {
      const Spec& s;
      std::size_t seen = 0;
      std::optional<std::string> failure;
      explicit C(const Spec& spec) : s(spec) {}
      void on_event(const turtle::LogEvent& e, const RunView&) override {
        if (failure || e.kind != "sense" || e.a != s.who) return;
        const json r = json::parse("{" + e.extra + "}", nullptr, false);
        if (!r.is_object() || r.value("sensor", std::string()) != s.sensor) return;
        const std::size_t k = seen++;
        const json& got_range = r["range"];
        const json& got_hit = r["hit"];
        const std::string where = "sense " + s.sensor + " of " + s.who + ", reading " + std::to_string(k) + " at t = " + num(e.t);
        if (s.min || s.max) {
          for (std::size_t j = 0; j < got_range.size(); ++j) {
            const double d = got_range[j].is_number() ? got_range[j].get<double>() : std::numeric_limits<double>::infinity();
            if ((s.min && d < *s.min) || (s.max && d > *s.max)) {
              failure = where + ": ray " + std::to_string(j) + " reads " + (got_range[j].is_number() ? num(d) : "null") +
                        ", wanted " + (s.min ? ">= " + num(*s.min) : std::string()) + (s.min && s.max ? " and " : "") +
                        (s.max ? "<= " + num(*s.max) : std::string());
              return;
            }
          }
        }
        if (k != s.reading || !(s.range || s.hit || s.colour)) return;
        if (s.range) {
          bool ok = got_range.size() == s.range->size();
          for (std::size_t j = 0; ok && j < got_range.size(); ++j) {
            const json& want = (*s.range)[j];
            const json& got = got_range[j];
            if (want.is_null() || got.is_null()) ok = want.is_null() && got.is_null();
            else ok = std::fabs(got.get<double>() - want.get<double>()) <= s.within;
          }
          if (!ok) failure = where + ": range " + got_range.dump() + ", wanted " + s.range->dump() + " within " + num(s.within);
        }
        if (!failure && s.hit && got_hit != *s.hit) failure = where + ": hit " + got_hit.dump() + ", wanted " + s.hit->dump();
        if (!failure && s.colour) {
          const json got_colour = r.contains("colour") ? r["colour"] : json();
          if (got_colour != *s.colour)
            failure = where + ": colour " + (got_colour.is_null() ? std::string("none (not a camera)") : got_colour.dump()) +
                      ", wanted " + s.colour->dump();
        }
      }
      std::optional<std::string> finish(const RunView& v) override {
        if (failure) return failure;
        if ((s.range || s.hit || s.colour) && seen <= s.reading)
          return "sense " + s.sensor + " of " + s.who + ": " + std::to_string(seen) + " readings by t = " + num(v.time()) +
                 ", wanted reading " + std::to_string(s.reading);
        if (seen == 0) return "sense " + s.sensor + " of " + s.who + ": no reading by t = " + num(v.time());
        return std::nullopt;
      }
    };
    return std::make_unique<C>(s_);
  }

 private:
  Spec s_;
};

std::shared_ptr<const Assertion> parse_sense(const json& e, const std::string& path, const ExpectParser& p) {
  p.check_keys(e, path, "sense", {"who", "reading", "range", "hit", "colour", "within", "min", "max"});
  SenseAssertion::Spec s;
  s.sensor = p.string(e.at("sense"), at(path, "sense"));
  if (!e.contains("who")) p.fail(path, "a sense expectation names its turtle: \"who\": \"t1\"");
  s.who = p.turtle_id(e.at("who"), at(path, "who"));
  if (auto it = e.find("reading"); it != e.end()) s.reading = whole(*it, at(path, "reading"), p);
  auto list = [&](const char* key, bool numbers) -> std::optional<json> {
    auto it = e.find(key);
    if (it == e.end()) return std::nullopt;
    const std::string lp = at(path, key);
    if (!it->is_array()) p.fail(lp, std::string(key) + " must be a list with an entry per ray (null: nothing within range)");
    for (std::size_t j = 0; j < it->size(); ++j) {
      const json& x = (*it)[j];
      if (!x.is_null() && !(numbers ? x.is_number() : x.is_string()))
        p.fail(at(lp, j), std::string("expected ") + (numbers ? "a distance" : "an id") + " or null, got " + x.dump());
    }
    return *it;
  };
  s.range = list("range", true);
  s.hit = list("hit", false);
  if (auto it = e.find("colour"); it != e.end()) {
    // A camera's pixels: colours as the world file writes them, compared as the camera reads them.
    const std::string cp = at(path, "colour");
    if (!it->is_array()) p.fail(cp, "colour must be a list with a colour per pixel, e.g. [\"#ffffff\", \"red\"]");
    json colours = json::array();
    for (std::size_t j = 0; j < it->size(); ++j) {
      const json& x = (*it)[j];
      const std::optional<std::string> c = x.is_string() ? turtle::parse_colour(x.get<std::string>()) : std::nullopt;
      if (!c) p.fail(at(cp, j), "expected a colour, \"#rrggbb\" or a name such as \"red\", got " + x.dump());
      colours.push_back(*c);
    }
    s.colour = std::move(colours);
  }
  if (auto it = e.find("within"); it != e.end()) s.within = p.non_negative(*it, at(path, "within"));
  if (auto it = e.find("min"); it != e.end()) s.min = p.non_negative(*it, at(path, "min"));
  if (auto it = e.find("max"); it != e.end()) s.max = p.non_negative(*it, at(path, "max"));
  if (!s.range && !s.hit && !s.colour && !s.min && !s.max)
    p.fail(path, "a sense expectation checks \"range\", \"hit\" and/or \"colour\" of one reading, or bounds \"min\"/\"max\" on every ray");
  return std::make_shared<SenseAssertion>(std::move(s));
}

}  // namespace

// ---- the table of kinds

const std::vector<AssertionKind>& assertion_kinds() {
  // An explicit table: one line per kind. The tag game adds {"it", ...} here.
  static const std::vector<AssertionKind> kinds = {
      {"event", "an event of this kind (and a, b) happens (after/before t)", parse_event},
      {"no_event", "no event of this kind (and a, b) happens (after/before t)", parse_no_event},
      {"count", "the number of events of this kind is within min..max", parse_count},
      {"inside", "the centres of `who` stay in a rectangle at every control step", parse_inside},
      {"near", "`who` is within a distance of a point at the end (or at t)", parse_near},
      {"heading", "turtle `who` heads this way (degrees) at the end (or at t)", parse_heading},
      {"speed", "a ball's or turtle's speed is within min..max at the end (or at t)", parse_speed},
      {"energy", "\"conserved\": relative change within tolerance at every control step", parse_energy},
      {"max_overlap", "no overlap deeper than this fraction of a radius", parse_max_overlap},
      {"it", "the game's \"it\" is this turtle at the end (or at t)", parse_it},
      {"walls", "the number of walls (all, or drawn_by a turtle) at the end", parse_walls},
      {"wall", "a wall with this id exists (or, with \"exists\": false, does not) at the end", parse_wall},
      {"sense", "a range sensor's reading (range, hit; a camera's colour) or every reading's bounds (min, max)", parse_sense},
  };
  return kinds;
}

}  // namespace turtlegas::world
