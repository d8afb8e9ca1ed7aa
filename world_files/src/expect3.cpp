// SPDX-License-Identifier: MIT
// The `expect` list of a 3-D world (expect3.hpp; docs/worlds.md, "Scripted 3-D worlds"). One class
// per kind, as in expect_kinds.cpp: what it checks at each event and each stop, and at the end.
#include "turtlegas/world/expect3.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include <nlohmann/json.hpp>

#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/world/file_error.hpp"
#include "turtlegas/world/json_read.hpp"

namespace turtlegas::world {

using nlohmann::json;
using sim::Vec3;

namespace {

std::string num(double v) {
  char b[32];
  const auto r = std::to_chars(b, b + sizeof b, v);
  return std::string(b, r.ptr);
}
std::string vec(Vec3 v) { return "[" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + "]"; }

}  // namespace

/// One run's checking of one entry: fed every event and every stop, asked at the end.
struct Check3 {
  virtual ~Check3() = default;
  virtual void on_event(const sim::Event3&) {}
  virtual void on_step(const sim::World3&) {}
  /// nullopt when the entry held, else what failed with times and values.
  virtual std::optional<std::string> finish(const sim::World3&) = 0;
};

struct Assertion3 {
  virtual ~Assertion3() = default;
  virtual std::unique_ptr<Check3> start(const sim::World3&) const = 0;
  /// Times other than the steps at which the run must stop, e.g. {"at": 2.5}.
  virtual std::vector<double> times() const { return {}; }
  std::size_t index = 0;  ///< in the `expect` list
};

namespace {

/// Reads entries with the loader's JSON paths, and resolves ids to the world's indices.
class Parser3 {
 public:
  Parser3(const std::string& file, const World3File& w) : rd_(file, JsonReader::Wording::value), w_(w) {
    for (std::size_t i = 0; i < w.ball_ids.size(); ++i) balls_[w.ball_ids[i]] = i;
    for (std::size_t i = 0; i < w.wall_ids.size(); ++i) walls_[w.wall_ids[i]] = i;
  }
  const JsonReader& rd() const { return rd_; }
  [[noreturn]] void fail(const std::string& path, const std::string& why) const { rd_.fail(path, why); }
  std::size_t ball(const json& v, const std::string& path) const {
    const std::string id = rd_.string(v, path);
    if (auto it = balls_.find(id); it != balls_.end()) return it->second;
    fail(path, "no ball has the id \"" + id + "\" (3-D worlds have balls and walls; give a ball's id)");
  }
  /// A ball (first: true) or a wall (first: false).
  std::pair<bool, std::size_t> body(const json& v, const std::string& path) const {
    const std::string id = rd_.string(v, path);
    if (auto it = balls_.find(id); it != balls_.end()) return {true, it->second};
    if (auto it = walls_.find(id); it != walls_.end()) return {false, it->second};
    fail(path, "no ball or wall has the id \"" + id + "\"");
  }
  Vec3 vec3(const json& v, const std::string& path) const {
    if (!v.is_array() || v.size() != 3) fail(path, "expected [x, y, z], three numbers, got " + rd_.got(v));
    return {rd_.number(v[0], path + "/0"), rd_.number(v[1], path + "/1"), rd_.number(v[2], path + "/2")};
  }
  std::optional<double> at(const json& e, const std::string& path) const {
    const json* a = rd_.find(e, "at");
    if (!a) return std::nullopt;
    if (a->is_string() && a->get<std::string>() == "end") return std::nullopt;
    if (!a->is_number()) fail(path + "/at", "expected \"end\" or a time in seconds, got " + rd_.got(*a));
    return rd_.non_negative(*a, path + "/at");
  }
  const json& need(const json& e, const std::string& path, std::string_view key, std::string_view kind) const {
    if (const json* v = rd_.find(e, key)) return *v;
    fail(path, std::string(kind) + " needs \"" + std::string(key) + "\"");
  }
  const std::string& ball_id(std::size_t i) const { return w_.ball_ids[i]; }
  const std::string& wall_id(std::size_t i) const { return w_.wall_ids[i]; }
  std::size_t balls() const { return w_.ball_ids.size(); }

 private:
  JsonReader rd_;
  const World3File& w_;
  std::map<std::string, std::size_t> balls_, walls_;
};

// ---- event filters: {"event"|"no_event"|"count": KIND, "a": ball, "b": ball or wall, "after", "before"}
struct Filter {
  sim::Event3Kind kind{};
  std::optional<std::size_t> a;
  std::optional<std::pair<bool, std::size_t>> b;
  double after = 0.0, before = std::numeric_limits<double>::infinity();
  std::string text;

  bool matches(const sim::Event3& e) const {
    if (e.kind != kind || e.t < after || !(e.t < before)) return false;
    if (e.kind == sim::Event3Kind::ball_ball) {
      // A pair is named either way round: the engine's order of the two is not the file's.
      if (b && !b->first) return false;
      auto is = [](const std::optional<std::size_t>& want, std::uint32_t got) { return !want || *want == got; };
      const std::optional<std::size_t> bb = b ? std::optional<std::size_t>(b->second) : std::nullopt;
      return (is(a, e.a) && is(bb, e.b)) || (is(a, e.b) && is(bb, e.a));
    }
    if (a && e.a != *a) return false;
    if (b && (b->first || e.kind == sim::Event3Kind::exit || e.b != b->second)) return false;
    return true;
  }
  static Filter parse(const json& e, const std::string& path, std::string_view key, const Parser3& p) {
    Filter f;
    const std::string k = p.rd().string(e.at(std::string(key)), path + "/" + std::string(key));
    static const std::map<std::string, sim::Event3Kind> kinds = {
        {"ball-ball", sim::Event3Kind::ball_ball}, {"ball-wall", sim::Event3Kind::ball_wall},
        {"ball-wall-edge", sim::Event3Kind::ball_wall_edge}, {"ball-wall-corner", sim::Event3Kind::ball_wall_corner},
        {"wedged", sim::Event3Kind::wedged},
        {"exit", sim::Event3Kind::exit}};
    const auto it = kinds.find(k);
    if (it == kinds.end())
      p.fail(path + "/" + std::string(key), "\"" + k + "\" is not an event of a 3-D world (one of: ball-ball, "
                                              "ball-wall, ball-wall-edge, ball-wall-corner, wedged, exit)");
    f.kind = it->second;
    f.text = k;
    if (const json* v = p.rd().find(e, "a")) {
      f.a = p.ball(*v, path + "/a");
      f.text += " a " + p.ball_id(*f.a);
    }
    if (const json* v = p.rd().find(e, "b")) {
      f.b = p.body(*v, path + "/b");
      f.text += " b " + (f.b->first ? p.ball_id(f.b->second) : p.wall_id(f.b->second));
    }
    if (const json* v = p.rd().find(e, "after")) f.after = p.rd().non_negative(*v, path + "/after");
    if (const json* v = p.rd().find(e, "before")) f.before = p.rd().non_negative(*v, path + "/before");
    if (f.after > 0.0) f.text += " after t = " + num(f.after);
    if (std::isfinite(f.before)) f.text += " before t = " + num(f.before);
    return f;
  }
};

/// count (min, max), event (min 1) and no_event (max 0) are one check.
class CountAssertion final : public Assertion3 {
 public:
  CountAssertion(std::string name, Filter f, std::optional<double> min, std::optional<double> max)
      : name_(std::move(name)), f_(std::move(f)), min_(min), max_(max) {}
  std::unique_ptr<Check3> start(const sim::World3&) const override {
    struct C final : Check3 {
      const CountAssertion& s;
      double n = 0.0, first = -1.0;
      explicit C(const CountAssertion& self) : s(self) {}
      void on_event(const sim::Event3& e) override {
        if (!s.f_.matches(e)) return;
        if (n == 0.0) first = e.t;
        n += 1.0;
      }
      std::optional<std::string> finish(const sim::World3&) override {
        if (s.name_ == "event" && n == 0.0) return "event " + s.f_.text + ": none happened";
        if (s.name_ == "no_event" && n > 0.0)
          return "no_event " + s.f_.text + ": " + num(n) + " happened, the first at t = " + num(first);
        const std::string head = "count " + s.f_.text + " = " + num(n) + ", wanted ";
        if (s.min_ && n < *s.min_) return head + ">= " + num(*s.min_);
        if (s.max_ && n > *s.max_) return head + "<= " + num(*s.max_);
        return std::nullopt;
      }
    };
    return std::make_unique<C>(*this);
  }

 private:
  std::string name_;
  Filter f_;
  std::optional<double> min_, max_;
};

// ---- one ball at one time: near, velocity, speed. "at": "end" (default) or a time.
class SampledAssertion final : public Assertion3 {
 public:
  enum class What { near, velocity, speed };
  SampledAssertion(What what, std::size_t who, std::string who_id, std::optional<double> when, Vec3 point,
                   double within, std::optional<double> min, std::optional<double> max)
      : what_(what), who_(who), who_id_(std::move(who_id)), at_(when), point_(point), within_(within), min_(min),
        max_(max) {}
  std::vector<double> times() const override { return at_ ? std::vector<double>{*at_} : std::vector<double>{}; }
  std::unique_ptr<Check3> start(const sim::World3&) const override {
    struct C final : Check3 {
      const SampledAssertion& s;
      bool sampled = false;
      std::optional<std::string> result;
      explicit C(const SampledAssertion& self) : s(self) {}
      void on_step(const sim::World3& w) override {
        if (sampled || !s.at_ || w.time() != *s.at_) return;
        sampled = true;
        result = s.test(w);
      }
      std::optional<std::string> finish(const sim::World3& w) override {
        if (!s.at_) return s.test(w);
        if (!sampled) return s.name() + ": the run ended at t = " + num(w.time()) + " before t = " + num(*s.at_);
        return result;
      }
    };
    return std::make_unique<C>(*this);
  }

 private:
  std::string name() const {
    return what_ == What::near ? "near " + vec(point_) : what_ == What::velocity ? "velocity " + vec(point_) : "speed";
  }
  std::optional<std::string> test(const sim::World3& w) const {
    const double t = w.time();
    if (!w.alive(who_)) return name() + ": " + who_id_ + " has left the arena by t = " + num(t);
    if (what_ == What::speed) {
      const double s = sim::norm(w.velocity(who_));
      const std::string head = "speed " + who_id_ + " = " + num(s) + " at t = " + num(t) + ", wanted ";
      if (min_ && !(s >= *min_)) return head + ">= " + num(*min_);
      if (max_ && !(s <= *max_)) return head + "<= " + num(*max_);
      return std::nullopt;
    }
    const Vec3 got = what_ == What::near ? w.position(who_) : w.velocity(who_);
    const double d = sim::norm(got - point_);
    if (d <= within_) return std::nullopt;
    return name() + ": " + who_id_ + (what_ == What::near ? " is at " : " moves at ") + vec(got) + " at t = " +
           num(t) + ", off by " + num(d) + ", wanted <= " + num(within_);
  }
  What what_;
  std::size_t who_;
  std::string who_id_;
  std::optional<double> at_;
  Vec3 point_;
  double within_ = 0.0;
  std::optional<double> min_, max_;
};

// ---- {"inside": [[x0, y0, z0], [x1, y1, z1]], "who": ...}: centres stay in the box at every stop
class InsideAssertion final : public Assertion3 {
 public:
  InsideAssertion(Vec3 lo, Vec3 hi, std::vector<std::size_t> who, std::vector<std::string> ids)
      : lo_(lo), hi_(hi), who_(std::move(who)), ids_(std::move(ids)) {}
  std::unique_ptr<Check3> start(const sim::World3&) const override {
    struct C final : Check3 {
      const InsideAssertion& s;
      std::optional<std::string> failure;
      explicit C(const InsideAssertion& self) : s(self) {}
      void on_step(const sim::World3& w) override {
        for (std::size_t k = 0; k < s.who_.size() && !failure; ++k) {
          const std::size_t i = s.who_[k];
          if (!w.alive(i)) {
            failure = "inside " + vec(s.lo_) + " " + vec(s.hi_) + ": " + s.ids_[k] + " has left the arena by t = " +
                      num(w.time());
            return;
          }
          const Vec3 p = w.position(i);
          for (int a = 0; a < 3; ++a)
            if (!(p[a] >= s.lo_[a] && p[a] <= s.hi_[a])) {
              failure = "inside " + vec(s.lo_) + " " + vec(s.hi_) + ": " + s.ids_[k] + " is at " + vec(p) +
                        " at t = " + num(w.time());
              return;
            }
        }
      }
      std::optional<std::string> finish(const sim::World3& w) override {
        on_step(w);
        return failure;
      }
    };
    return std::make_unique<C>(*this);
  }

 private:
  Vec3 lo_, hi_;
  std::vector<std::size_t> who_;
  std::vector<std::string> ids_;
};

// ---- {"energy": "conserved", "tolerance": r}: |E(t) - E(0)| <= r |E(0)| at every stop
class EnergyAssertion final : public Assertion3 {
 public:
  explicit EnergyAssertion(double tol) : tol_(tol) {}
  std::unique_ptr<Check3> start(const sim::World3& w) const override {
    struct C final : Check3 {
      double tol, e0, worst = 0.0, when = 0.0;
      C(double t, double e) : tol(t), e0(e) {}
      void on_step(const sim::World3& w) override {
        const double d = std::abs(w.energy() - e0);
        if (d > worst) worst = d, when = w.time();
      }
      std::optional<std::string> finish(const sim::World3& w) override {
        on_step(w);
        if (worst <= tol * std::abs(e0)) return std::nullopt;
        return "energy conserved: off by " + num(worst / std::abs(e0)) + " of " + num(e0) + " at t = " + num(when) +
               ", wanted <= " + num(tol);
      }
    };
    return std::make_unique<C>(tol_, w.energy());
  }

 private:
  double tol_;
};

// ---- {"max_overlap": f}: no overlap deeper than f of the smaller radius, at every stop and contact
class OverlapAssertion final : public Assertion3 {
 public:
  explicit OverlapAssertion(double f) : f_(f) {}
  std::unique_ptr<Check3> start(const sim::World3&) const override {
    struct C final : Check3 {
      double f, worst = 0.0, when = 0.0;
      explicit C(double v) : f(v) {}
      void on_step(const sim::World3& w) override {
        const double o = w.max_overlap_now();
        if (o > worst) worst = o, when = w.time();
      }
      std::optional<std::string> finish(const sim::World3& w) override {
        on_step(w);
        if (worst > f)
          return "max_overlap: " + num(worst) + " of a radius at t = " + num(when) + ", wanted <= " + num(f);
        if (w.max_contact_error() > f)
          return "max_overlap: a contact was served " + num(w.max_contact_error()) + " of a radius off, wanted <= " +
                 num(f);
        return std::nullopt;
      }
    };
    return std::make_unique<C>(f_);
  }

 private:
  double f_;
};

std::optional<double> bound(const json& e, const std::string& path, std::string_view key, const Parser3& p) {
  if (const json* v = p.rd().find(e, key)) return p.rd().non_negative(*v, path + "/" + std::string(key));
  return std::nullopt;
}

}  // namespace

const std::vector<std::string_view>& expect3_kinds() {
  static const std::vector<std::string_view> kinds = {"until",  "mode",  "event", "no_event",   "count",      "inside",
                                                      "near",   "velocity", "speed", "energy", "max_overlap"};
  return kinds;
}

Expectations3 parse_expect3(std::string_view text, const std::string& file, const World3File& w) {
  const json doc = json::parse(text.begin(), text.end(), nullptr, false);
  Parser3 p(file, w);
  Expectations3 out;
  if (const json* dt = p.rd().find(doc, "dt")) out.dt = p.rd().positive(*dt, "/dt", "dt");
  const json* list = p.rd().find(doc, "expect");
  if (!list) return out;
  out.present = true;
  p.rd().expect_array(*list, "/expect", "expect");
  for (std::size_t k = 0; k < list->size(); ++k) {
    const std::string path = "/expect/" + std::to_string(k);
    const json& e = (*list)[k];
    p.rd().expect_object(e, path, "an expectation");
    std::string kind;
    for (const auto& [key, v] : e.items()) {
      if (std::find(expect3_kinds().begin(), expect3_kinds().end(), key) == expect3_kinds().end()) continue;
      if (!kind.empty()) p.fail(path, "names two kinds, \"" + kind + "\" and \"" + key + "\"; give one per entry");
      kind = key;
    }
    if (kind.empty()) {
      std::string known;
      for (auto n : expect3_kinds()) known += (known.empty() ? "" : ", ") + std::string(n);
      p.fail(path, "no assertion kind; a 3-D expectation names one of: " + known);
    }
    auto keys = [&](std::initializer_list<std::string_view> also) {
      std::vector<std::string_view> all(also);
      for (const auto& [key, v] : e.items())
        if (key != kind && key.rfind("x-", 0) != 0 && std::find(all.begin(), all.end(), key) == all.end()) {
          std::string known;
          for (auto n : all) known += (known.empty() ? "" : ", ") + std::string(n);
          p.fail(path + "/" + key, "unknown key \"" + key + "\" in a \"" + kind + "\" expectation (its keys: " +
                                       (known.empty() ? "none" : known) + ")");
        }
    };
    std::shared_ptr<Assertion3> a;
    if (kind == "until") {
      keys({});
      out.until = p.rd().non_negative(e["until"], path + "/until");
      continue;
    }
    if (kind == "mode") {
      keys({});
      const std::string m = p.rd().string(e["mode"], path + "/mode");
      if (const auto mode = sim::mode_from_string(m)) out.modes = {*mode};
      else if (m == "both") out.modes = {sim::Mode::exact, sim::Mode::step};
      else p.fail(path + "/mode", "mode must be \"exact\", \"step\" or \"both\" (got \"" + m + "\")");
      continue;
    }
    if (kind == "event" || kind == "no_event" || kind == "count") {
      if (kind == "count") keys({"a", "b", "after", "before", "min", "max"});
      else keys({"a", "b", "after", "before"});
      std::optional<double> min = kind == "event" ? std::optional<double>(1.0) : std::nullopt;
      std::optional<double> max = kind == "no_event" ? std::optional<double>(0.0) : std::nullopt;
      if (kind == "count") {
        min = bound(e, path, "min", p), max = bound(e, path, "max", p);
        if (!min && !max) p.fail(path, "count needs \"min\" or \"max\" or both");
        if (min && max && *min > *max) p.fail(path + "/min", "min (" + num(*min) + ") is more than max (" + num(*max) + ")");
      }
      a = std::make_shared<CountAssertion>(kind, Filter::parse(e, path, kind, p), min, max);
    } else if (kind == "near" || kind == "velocity") {
      keys({"who", "within", "at"});
      const Vec3 point = p.vec3(e[kind], path + "/" + kind);
      const std::size_t who = p.ball(p.need(e, path, "who", kind), path + "/who");
      const double within = p.rd().non_negative(p.need(e, path, "within", kind), path + "/within");
      a = std::make_shared<SampledAssertion>(kind == "near" ? SampledAssertion::What::near
                                                            : SampledAssertion::What::velocity,
                                             who, p.ball_id(who), p.at(e, path), point, within, std::nullopt,
                                             std::nullopt);
    } else if (kind == "speed") {
      keys({"min", "max", "at"});
      const std::size_t who = p.ball(e["speed"], path + "/speed");
      const auto min = bound(e, path, "min", p), max = bound(e, path, "max", p);
      if (!min && !max) p.fail(path, "speed needs \"min\" or \"max\" or both");
      a = std::make_shared<SampledAssertion>(SampledAssertion::What::speed, who, p.ball_id(who), p.at(e, path), Vec3{},
                                             0.0, min, max);
    } else if (kind == "inside") {
      keys({"who"});
      const json& box = e["inside"];
      if (!box.is_array() || box.size() != 2) p.fail(path + "/inside", "expected [[x0, y0, z0], [x1, y1, z1]], got " + p.rd().got(box));
      const Vec3 lo = p.vec3(box[0], path + "/inside/0"), hi = p.vec3(box[1], path + "/inside/1");
      std::vector<std::size_t> who;
      const json* w_ = p.rd().find(e, "who");
      if (!w_ || (w_->is_string() && w_->get<std::string>() == "*")) {
        for (std::size_t i = 0; i < p.balls(); ++i) who.push_back(i);
      } else if (w_->is_array()) {
        for (std::size_t i = 0; i < w_->size(); ++i) who.push_back(p.ball((*w_)[i], path + "/who/" + std::to_string(i)));
      } else {
        who.push_back(p.ball(*w_, path + "/who"));
      }
      std::vector<std::string> ids;
      for (std::size_t i : who) ids.push_back(p.ball_id(i));
      a = std::make_shared<InsideAssertion>(lo, hi, who, ids);
    } else if (kind == "energy") {
      keys({"tolerance"});
      if (p.rd().string(e["energy"], path + "/energy") != "conserved")
        p.fail(path + "/energy", "energy must be \"conserved\" (got " + p.rd().got(e["energy"]) + ")");
      a = std::make_shared<EnergyAssertion>(p.rd().non_negative(p.need(e, path, "tolerance", "energy"), path + "/tolerance"));
    } else {  // max_overlap
      keys({});
      if (w.def.spheres.size() > 4096)
        p.fail(path, "max_overlap is measured over every pair, for up to 4096 spheres; this world has " +
                         std::to_string(w.def.spheres.size()));
      a = std::make_shared<OverlapAssertion>(p.rd().non_negative(e["max_overlap"], path + "/max_overlap"));
    }
    a->index = k;
    out.entries.push_back(std::move(a));
  }
  return out;
}

Expect3Result run_expect3(const World3File& w, const Expectations3& e,
                          const std::function<void(const sim::World3&)>& on_step) {
  sim::World3 world(w.def);
  std::vector<std::unique_ptr<Check3>> checks;
  std::set<double> stops;
  for (const auto& a : e.entries) {
    checks.push_back(a->start(world));
    for (double t : a->times())
      if (t <= e.until) stops.insert(t);
  }
  // The control steps k dt (k integer, not a sum of dt's), the named times and the end.
  for (double k = 1.0; k * e.dt < e.until; k += 1.0) stops.insert(k * e.dt);
  stops.insert(e.until);
  auto step = [&] {
    for (auto& c : checks) c->on_step(world);
    if (on_step) on_step(world);
  };
  step();
  std::vector<sim::Event3> log;
  for (double t : stops) {
    log.clear();
    world.advance_to(t, &log);
    for (const sim::Event3& ev : log)
      for (auto& c : checks) c->on_event(ev);
    step();
  }
  Expect3Result r;
  r.assertions = checks.size();
  for (std::size_t k = 0; k < checks.size(); ++k)
    if (auto f = checks[k]->finish(world)) r.failures.push_back("expect[" + std::to_string(e.entries[k]->index) + "] " + *f);
  return r;
}

}  // namespace turtlegas::world
