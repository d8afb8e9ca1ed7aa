// SPDX-License-Identifier: MIT
// `turtlegas sweep`: the spec, its runs, the journal that makes a sweep resumable, local children
// and MPI ranks, one results file. Just over 600 lines: the local and the MPI schedulers share the
// journal and results code in this file, and splitting them apart would expose it for two callers.
#include "sweep_command.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#ifdef TURTLEGAS_HAVE_MPI
#include <mpi.h>
#endif

#include "child_processes.hpp"
#include "cli_common.hpp"
#include "output_file.hpp"
#include "run_loop.hpp"
#include "signals.hpp"
#include "turtlegas/formats/stats_file.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/world/scenario.hpp"
#include "turtlegas/world/tag_tournament.hpp"
#include "turtlegas/world/world_file.hpp"
#include "turtlegas/turtle/json_depth.hpp"

namespace turtlegas::apps {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr std::size_t max_runs = 10'000'000;

/// A sweep specification (docs/sweeps.md).
struct Spec {
  std::string file;         ///< the spec, as given
  nlohmann::ordered_json text;  ///< the spec as read, in its order (the results' first line)
  std::string world_file;   ///< resolved against the spec's folder
  json world;               ///< the world file's JSON
  double until = 0.0;
  sim::Mode mode = sim::Mode::exact;
  std::vector<std::uint64_t> seeds;
  std::vector<std::pair<std::string, std::vector<json>>> grid;  ///< pointer -> values, in the spec's order
  std::vector<std::string> summary;                             ///< pointers into a result line
  std::size_t runs = 0;
};

std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

/// json::parse(text, nullptr, false), with a text nested too deep (turtle::json_too_deep) discarded
/// as invalid JSON is: a journal line or a child's report that no run wrote.
json parse_or_discard(const std::string& text) {
  if (turtle::json_too_deep(text)) return json(json::value_t::discarded);
  return json::parse(text, nullptr, false);
}

json read_json_file(const std::string& file, const std::string& what) {
  std::ifstream in(file);
  if (!in) throw BadInput(file + ": no such file (" + what + ")");
  std::stringstream s;
  s << in.rdbuf();
  if (const auto deep = turtle::json_too_deep(s.str())) throw BadInput(file + ": " + *deep + " (" + what + ")");
  json j = json::parse(s.str(), nullptr, false);
  if (j.is_discarded()) throw BadInput(file + ": invalid JSON (" + what + ")");
  return j;
}

Spec parse_spec(const std::string& file) {
  Spec spec;
  spec.file = file;
  // The spec's own keys keep their order (grid axes are expanded in the order written).
  {
    std::ifstream in(file);
    if (!in) throw BadInput(file + ": no such file (the sweep spec)");
    std::stringstream s;
    s << in.rdbuf();
    if (const auto deep = turtle::json_too_deep(s.str())) throw BadInput(file + ": " + *deep + " (the sweep spec)");
    spec.text = nlohmann::ordered_json::parse(s.str(), nullptr, false);
    if (spec.text.is_discarded()) throw BadInput(file + ": invalid JSON (the sweep spec)");
  }
  const nlohmann::ordered_json& ordered = spec.text;
  auto bad = [&](const std::string& path, const std::string& what) { return BadInput(file + ": " + path + ": " + what); };
  if (!ordered.is_object()) throw bad("/", "a sweep spec is a JSON object");
  for (const auto& [k, v] : ordered.items())
    if (k != "format" && k != "world" && k != "until" && k != "mode" && k != "seeds" && k != "grid" && k != "summary" &&
        k.rfind("x-", 0) != 0)
      throw bad("/" + k, "unknown key; a sweep spec has format, world, until, mode, seeds, grid, summary (and x-...)");
  if (ordered.value("format", "") != "turtlegas-sweep/1") throw bad("/format", "must be \"turtlegas-sweep/1\"");
  if (!ordered.contains("world") || !ordered["world"].is_string())
    throw bad("/world", "the world file to sweep, relative to this file");
  const fs::path world_path = fs::path(ordered["world"].get<std::string>());
  spec.world_file = (world_path.is_absolute() ? world_path : fs::path(file).parent_path() / world_path).lexically_normal().string();
  spec.world = read_json_file(spec.world_file, "the world of sweep " + file);
  if (!ordered.contains("until") || !ordered["until"].is_number() || !std::isfinite(ordered["until"].get<double>()) ||
      ordered["until"].get<double>() <= 0.0)
    throw bad("/until", "simulated seconds per run, a number > 0");
  spec.until = ordered["until"].get<double>();
  const std::string mode = ordered.value("mode", "exact");
  const auto m = sim::mode_from_string(mode);
  if (!m) throw bad("/mode", "exact or step (got \"" + mode + "\")");
  spec.mode = *m;
  const auto& seeds = ordered.contains("seeds") ? ordered["seeds"] : nlohmann::ordered_json();
  if (seeds.is_array() && !seeds.empty()) {
    for (const auto& s : seeds) {
      if (!s.is_number_unsigned()) throw bad("/seeds", "a list of seeds, integers >= 0");
      spec.seeds.push_back(s.get<std::uint64_t>());
    }
  } else if (seeds.is_object() && seeds.contains("count") && seeds["count"].is_number_unsigned() &&
             seeds["count"].get<std::uint64_t>() >= 1) {
    const std::uint64_t first = seeds.value("first", std::uint64_t{1});
    for (std::uint64_t k = 0; k < seeds["count"].get<std::uint64_t>() && k < max_runs; ++k) spec.seeds.push_back(first + k);
  } else {
    throw bad("/seeds", "a list of seeds, [1, 2, 3], or {\"count\": N, \"first\": 1}");
  }
  std::set<std::uint64_t> distinct(spec.seeds.begin(), spec.seeds.end());
  if (distinct.size() != spec.seeds.size()) throw bad("/seeds", "a seed is named twice");
  if (ordered.contains("grid")) {
    if (!ordered["grid"].is_object()) throw bad("/grid", "an object, JSON pointer -> list of values");
    for (const auto& [ptr, values] : ordered["grid"].items()) {
      const std::string path = "/grid/" + ptr;
      if (!values.is_array() || values.empty()) throw bad(path, "a non-empty list of values");
      std::vector<json> vs;
      for (const auto& v : values) {
        json probe = spec.world;
        try {
          probe[json::json_pointer(ptr)] = json::parse(v.dump());
        } catch (const json::exception& e) {
          throw bad(path, "not a JSON pointer into the world file (" + std::string(e.what()) + ")");
        }
        vs.push_back(json::parse(v.dump()));
      }
      spec.grid.emplace_back(ptr, std::move(vs));
    }
  }
  if (ordered.contains("summary")) {
    if (!ordered["summary"].is_array()) throw bad("/summary", "a list of JSON pointers into a result line");
    for (const auto& p : ordered["summary"]) {
      if (!p.is_string()) throw bad("/summary", "a list of JSON pointers into a result line");
      try {
        json::json_pointer check(p.get<std::string>());
      } catch (const json::exception&) {
        throw bad("/summary", "\"" + p.get<std::string>() + "\" is not a JSON pointer");
      }
      spec.summary.push_back(p.get<std::string>());
    }
  } else {
    spec.summary = {"/stats/collisions", "/stats/energy_end"};
  }
  std::size_t points = 1;
  for (const auto& [ptr, values] : spec.grid) {
    points *= values.size();
    if (points > max_runs) throw bad("/grid", "more than " + std::to_string(max_runs) + " runs");
  }
  spec.runs = points * spec.seeds.size();
  if (spec.runs > max_runs) throw bad("/seeds", "more than " + std::to_string(max_runs) + " runs");
  return spec;
}

/// Run k's grid point (one value index per axis, the first axis slowest) and seed.
std::pair<std::vector<std::size_t>, std::uint64_t> decompose(const Spec& spec, std::size_t k) {
  const std::uint64_t seed = spec.seeds[k % spec.seeds.size()];
  std::size_t g = k / spec.seeds.size();
  std::vector<std::size_t> idx(spec.grid.size());
  for (std::size_t a = spec.grid.size(); a-- > 0;) {
    idx[a] = g % spec.grid[a].second.size();
    g /= spec.grid[a].second.size();
  }
  return {idx, seed};
}

json overrides_of(const Spec& spec, const std::vector<std::size_t>& idx) {
  json o = json::object();
  for (std::size_t a = 0; a < spec.grid.size(); ++a) o[spec.grid[a].first] = spec.grid[a].second[idx[a]];
  return o;
}

/// Runs run k in this process: its result line (without a newline). Deterministic: no wall-clock
/// figures in it.
json run_one(const Spec& spec, std::size_t k, const turtle::Registry& registry, const turtle::ServerOptions& base) {
  const auto [idx, seed] = decompose(spec, k);
  const json overrides = overrides_of(spec, idx);
  json w = spec.world;
  for (const auto& [ptr, value] : overrides.items()) w[json::json_pointer(ptr)] = value;
  w["seed"] = seed;
  const std::string label = spec.world_file + " (sweep run " + std::to_string(k) + ")";
  world::Scene scene;
  try {
    scene = world::parse_scene(w.dump(), label, registry);
  } catch (const world::WorldFileError& e) {
    throw BadInput(e.what());
  }
  turtle::ServerOptions options = base;
  options.mode = spec.mode;
  json line = {{"run", k}, {"seed", seed}, {"overrides", overrides}};
  formats::RunFigures run;
  run.world = spec.text["world"].get<std::string>();  // as the spec says: the results do not depend on where it lies
  run.name = scene.def.name;
  run.mode = spec.mode;
  run.until = spec.until;
  run.dt = scene.def.dt;
  run.seed = seed;
  run.balls = scene.def.balls.size();
  run.turtles = scene.def.turtles.size();
  json stats;
  if (scene.def.turtles.empty()) {
    sim::World world = make_world(scene.def, spec.mode, label);
    run.energy_start = world.energy();
    world.advance_to(spec.until);
    for (std::size_t i = 0; i < world.ball_count(); ++i) run.balls_alive += world.ball(i).alive ? 1 : 0;
    run.energy_end = world.energy();
    const sim::Overlap now = world.measure_overlap(), seen = world.max_contact_overlap();
    run.max_overlap = std::max(now.depth, seen.depth);
    run.max_overlap_relative = std::max(now.relative, seen.relative);
    stats = formats::stats_json(run, world);
  } else {
    auto server = make_server(scene, registry, options, label);
    std::vector<turtle::LogEvent> events;
    server->set_event_log(&events);
    run.energy_start = server->world().energy();
    server->run_until(spec.until);
    server->set_event_log(nullptr);
    for (const auto& e : events) run.touches += e.kind == "touch", run.faults += e.kind == "fault";
    for (std::size_t i = 0; i < server->turtle_count(); ++i) run.turtles_finished += server->turtle(i).finished ? 1 : 0;
    const sim::World& world = server->world();
    for (std::size_t i = 0; i < world.ball_count(); ++i) run.balls_alive += world.ball(i).alive ? 1 : 0;
    run.energy_end = world.energy();
    const sim::Overlap now = world.measure_overlap(), seen = world.max_contact_overlap();
    run.max_overlap = std::max(now.depth, seen.depth);
    run.max_overlap_relative = std::max(now.relative, seen.relative);
    stats = formats::stats_json(run, world);
    if (server->game()) line["tag"] = server->game()->score(server->time());
  }
  // Wall-clock figures differ from run to run of the same input: they stay out of the results.
  stats.erase("wall_seconds");
  stats.erase("collisions_per_second");
  line["stats"] = stats;
  if (scene.expect.present && scene.expect.until) {
    world::ExpectResult r;
    try {
      r = world::run_expectations(scene, registry, spec.mode, options);
    } catch (const std::invalid_argument& e) {
      throw BadInput(label + ": " + e.what());
    }
    line["expect"] = {{"passed", r.passed()}, {"assertions", r.assertions}, {"failures", r.failures}};
  }
  return line;
}

/// The results so far: run index -> its line.
using Results = std::map<std::size_t, std::string>;

std::string fingerprint(const Spec& spec) {
  char b[32];
  std::snprintf(b, sizeof b, "%016llx",
                static_cast<unsigned long long>(fnv1a(spec.text.dump() + "\n" + spec.world.dump())));
  return b;
}

/// The journal beside the results (<out>.partial): a header line with the spec's fingerprint,
/// then one line per finished run, appended as each ends. A line cut short by a kill is dropped.
class Journal {
 public:
  Journal(const std::string& out, const Spec& spec, Results& results) : path_(out + ".partial") {
    const std::string fp = fingerprint(spec);
    std::vector<std::string> good;
    if (fs::exists(path_)) {
      std::ifstream in(path_);
      std::string line;
      bool first = true;
      while (std::getline(in, line)) {
        const json j = parse_or_discard(line);
        if (first) {
          first = false;
          if (j.is_discarded() || j.value("fingerprint", "") != fp)
            throw BadInput(path_ + ": a partial sweep of another spec or world (delete it, or choose another --out)");
          continue;
        }
        if (j.is_discarded() || !j.contains("run") || !j["run"].is_number_unsigned() || in.eof()) continue;
        const std::size_t k = j["run"].get<std::size_t>();
        if (k < spec.runs && !results.count(k)) {
          results[k] = line;
          good.push_back(line);
        }
      }
    }
    // Rewritten whole (a cut line gone), then appended to.
    {
      std::ofstream rewrite(path_ + ".tmp", std::ios::trunc);
      rewrite << json{{"fingerprint", fp}, {"spec", spec.file}}.dump() << '\n';
      for (const std::string& l : good) rewrite << l << '\n';
      if (!rewrite) throw BadInput(path_ + ": cannot write the sweep's journal here");
    }
    fs::rename(path_ + ".tmp", path_);
    out_.open(path_, std::ios::app);
    if (!out_) throw BadInput(path_ + ": cannot write the sweep's journal here");
  }
  void record(const std::string& line) {
    out_ << line << '\n';
    out_.flush();
  }
  void remove() {
    out_.close();
    fs::remove(path_);
  }

 private:
  std::string path_;
  std::ofstream out_;
};

std::string fixed(double v, int digits) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

/// Per grid point, the mean and 95 % t-interval of each summary pointer over the seeds.
std::string summary_table(const Spec& spec, const Results& results) {
  const std::size_t points = spec.runs / spec.seeds.size();
  std::string out = "grid point";
  std::vector<std::string> labels;
  std::size_t width = 10;
  for (std::size_t g = 0; g < points; ++g) {
    const auto [idx, seed] = decompose(spec, g * spec.seeds.size());
    std::string l;
    for (std::size_t a = 0; a < spec.grid.size(); ++a)
      l += (l.empty() ? "" : " ") + spec.grid[a].first + "=" + spec.grid[a].second[idx[a]].dump();
    if (l.empty()) l = "(no grid)";
    labels.push_back(l);
    width = std::max(width, l.size());
  }
  char buf[512];
  std::snprintf(buf, sizeof buf, "%-*s  %5s", static_cast<int>(width), "grid point", "runs");
  out = buf;
  for (const std::string& p : spec.summary) {
    std::snprintf(buf, sizeof buf, "  %26s", (p + " (95%)").c_str());
    out += buf;
  }
  out += "\n";
  for (std::size_t g = 0; g < points; ++g) {
    std::vector<std::vector<double>> x(spec.summary.size());
    std::size_t n = 0;
    for (std::size_t s = 0; s < spec.seeds.size(); ++s) {
      auto it = results.find(g * spec.seeds.size() + s);
      if (it == results.end()) continue;
      ++n;
      const json j = json::parse(it->second);
      for (std::size_t q = 0; q < spec.summary.size(); ++q) {
        const json::json_pointer ptr(spec.summary[q]);
        if (j.contains(ptr) && j.at(ptr).is_number()) x[q].push_back(j.at(ptr).get<double>());
      }
    }
    std::snprintf(buf, sizeof buf, "%-*s  %5zu", static_cast<int>(width), labels[g].c_str(), n);
    out += buf;
    for (const auto& v : x) {
      std::string cell = "-";
      if (!v.empty()) {
        double m = 0;
        for (double a : v) m += a;
        m /= static_cast<double>(v.size());
        cell = fixed(m, 6);
        if (v.size() > 1) {
          double ss = 0;
          for (double a : v) ss += (a - m) * (a - m);
          const double hw = world::t_quantile_975(static_cast<double>(v.size() - 1)) *
                            std::sqrt(ss / static_cast<double>(v.size() - 1)) / std::sqrt(static_cast<double>(v.size()));
          cell += " +/- " + fixed(hw, 3);
        }
      }
      std::snprintf(buf, sizeof buf, "  %26s", cell.c_str());
      out += buf;
    }
    out += "\n";
  }
  return out;
}

/// The results file: a header line, then every run's line in run order. The same for any --jobs,
/// any number of MPI ranks, and a resumed sweep.
void write_results(const std::string& out, const Spec& spec, const Results& results) {
  OutputFile f(out, "--out");
  nlohmann::ordered_json header;
  header["format"] = "turtlegas-sweep-results/1";
  header["spec"] = spec.text;
  header["runs"] = spec.runs;
  f.stream() << header.dump() << '\n';
  for (const auto& [k, line] : results) f.stream() << line << '\n';
  f.commit();
}

std::string default_out(const std::string& spec) {
  return fs::path(spec).stem().string() + ".results.jsonl";
}

int finish(const SweepOptions& options, const std::string& out, const Spec& spec, Results& results, Journal& journal,
           std::size_t failed) {
  std::fputs(summary_table(spec, results).c_str(), stdout);
  if (results.size() == spec.runs) {
    write_results(out, spec, results);
    journal.remove();
    std::printf("%zu runs; results in %s\n", spec.runs, out.c_str());
    return exit_ok;
  }
  std::printf("%zu of %zu runs have results (%zu failed); run the same command again to retry the rest\n",
              results.size(), spec.runs, failed);
  (void)options;
  return exit_failure;
}

turtle::ServerOptions server_options(const SweepOptions& o) {
  turtle::ServerOptions s;
  s.stack_bytes = o.stack_kib * 1024;
  s.program_budget = o.program_budget;
  return s;
}

/// Whether this process was started by mpirun (Open MPI, or a PMI launcher).
int launcher_size() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* s = std::getenv(v)) return std::atoi(s);
  return 0;
}

int run_local(const SweepOptions& options, const turtle::Registry&, const std::vector<std::string>& plugins,
              const Spec& spec, const std::string& out) {
  Results results;
  Journal journal(out, spec, results);
  std::vector<std::size_t> pending;
  for (std::size_t k = 0; k < spec.runs; ++k)
    if (!results.count(k)) pending.push_back(k);
  if (!results.empty() && !options.quiet)
    spdlog::info("sweep: resuming: {} of {} runs already recorded in {}.partial", results.size(), spec.runs, out);
  std::vector<std::vector<std::string>> args;
  for (std::size_t k : pending) {
    std::vector<std::string> a = {"sweep", spec.file, "--run", std::to_string(k), "--stack-kib",
                                  std::to_string(options.stack_kib), "--program-budget", json(options.program_budget).dump()};
    for (const std::string& p : plugins) a.insert(a.end(), {"--plugin", p});
    args.push_back(std::move(a));
  }
  std::size_t failed = 0;
  StatusLine status(!options.quiet);
  auto on_done = [&](std::size_t i, ChildResult&& r) {
    const std::size_t k = pending[i];
    status.clear();
    if (r.stopped) return;  // killed at SIGINT or SIGTERM: left for the resumed sweep
    const json j = parse_or_discard(r.report);
    if (!r.timed_out && r.exited && r.exit_code == 0 && !j.is_discarded() && j.value("run", std::size_t(-1)) == k) {
      std::string line = r.report;
      while (!line.empty() && line.back() == '\n') line.pop_back();
      journal.record(line);
      results[k] = std::move(line);
      if (!options.quiet) spdlog::info("sweep: run {} done ({} of {})", k, results.size(), spec.runs);
    } else {
      ++failed;
      std::string why = r.timed_out ? "ran past --timeout" : r.how_it_ended();
      spdlog::error("sweep: run {} failed: {}{}{}", k, why, r.err.empty() ? "" : "\n", r.err);
    }
  };
  // "12 of 40 runs done; running: run 12 (4 s), run 13 (1 s)".
  auto on_tick = [&](const std::vector<RunningChild>& running) {
    if (!status.due()) return;
    std::string text = std::to_string(results.size()) + " of " + std::to_string(spec.runs) + " runs done; running:";
    for (std::size_t k = 0; k < running.size() && k < 6; ++k)
      text += (k > 0 ? ", run " : " run ") + std::to_string(pending[running[k].index]) + " (" +
              human_duration(running[k].seconds) + ")";
    if (running.size() > 6) text += " and " + std::to_string(running.size() - 6) + " more";
    status.show(text);
  };
  install_stop_signals("stopping the runs; the results so far are kept for the next sweep");
  const int stopped_by = run_children(args, options.jobs, options.timeout, {on_done, on_tick});
  status.clear();
  if (stopped_by != 0) {
    // The journal holds every run that ended, each line whole: the same command goes on from there.
    std::printf("stopped by %s: %zu of %zu runs have results in %s.partial; run the same command again to go on\n",
                signal_name(stopped_by), results.size(), spec.runs, out.c_str());
    return exit_code_for(stopped_by);
  }
  return finish(options, out, spec, results, journal, failed);
}

#ifdef TURTLEGAS_HAVE_MPI
constexpr int tag_ready = 1, tag_result = 2, tag_work = 3, tag_stop = 4;

/// Rank 0: hands out runs one at a time to whichever worker asks, gathers their lines.
int mpi_master(const SweepOptions& options, const Spec& spec, const std::string& out, int size) {
  Results results;
  Journal journal(out, spec, results);
  std::vector<std::size_t> pending;
  for (std::size_t k = 0; k < spec.runs; ++k)
    if (!results.count(k)) pending.push_back(k);
  std::size_t next = 0, failed = 0;
  int active = size - 1;
  while (active > 0) {
    MPI_Status st;
    MPI_Probe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &st);
    int count = 0;
    MPI_Get_count(&st, MPI_CHAR, &count);
    std::string msg(static_cast<std::size_t>(count), '\0');
    MPI_Recv(msg.data(), count, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (st.MPI_TAG == tag_result) {
      const json j = parse_or_discard(msg);
      if (!j.is_discarded() && j.contains("error")) {
        ++failed;
        spdlog::error("sweep: run {} failed on rank {}: {}", j.value("run", 0), st.MPI_SOURCE, j.value("error", ""));
      } else if (!j.is_discarded()) {
        const std::size_t k = j.at("run").get<std::size_t>();
        journal.record(msg);
        results[k] = msg;
        if (!options.quiet) spdlog::info("sweep: run {} done on rank {} ({} of {})", k, st.MPI_SOURCE, results.size(), spec.runs);
      }
    }
    if (next < pending.size()) {
      const std::uint64_t k = pending[next++];
      MPI_Send(&k, 1, MPI_UINT64_T, st.MPI_SOURCE, tag_work, MPI_COMM_WORLD);
    } else {
      const std::uint64_t none = 0;
      MPI_Send(&none, 1, MPI_UINT64_T, st.MPI_SOURCE, tag_stop, MPI_COMM_WORLD);
      --active;
    }
  }
  return finish(options, out, spec, results, journal, failed);
}

/// Ranks 1 ... K-1: ask for a run, run it here, send its line, until told to stop.
int mpi_worker(const SweepOptions& options, const Spec& spec, const turtle::Registry& registry) {
  std::string msg;
  int tag = tag_ready;
  for (;;) {
    MPI_Send(msg.data(), static_cast<int>(msg.size()), MPI_CHAR, 0, tag, MPI_COMM_WORLD);
    std::uint64_t k = 0;
    MPI_Status st;
    MPI_Recv(&k, 1, MPI_UINT64_T, 0, MPI_ANY_TAG, MPI_COMM_WORLD, &st);
    if (st.MPI_TAG == tag_stop) return exit_ok;
    try {
      msg = run_one(spec, static_cast<std::size_t>(k), registry, server_options(options)).dump();
    } catch (const std::exception& e) {
      msg = json{{"run", k}, {"error", e.what()}}.dump();
    }
    tag = tag_result;
  }
}
#endif

}  // namespace

bool sweep_has_mpi() {
#ifdef TURTLEGAS_HAVE_MPI
  return true;
#else
  return false;
#endif
}

CLI::App* add_sweep_command(CLI::App& app, SweepOptions& options) {
  CLI::App* cmd = app.add_subcommand(
      "sweep", "Run a grid of world-file overrides x seeds (a sweep spec), locally (--jobs) or under mpirun; "
               "results in one JSON-lines file, resumable");
  cmd->add_option("spec", options.spec, "Sweep spec (format turtlegas-sweep/1, docs/sweeps.md)")->required();
  cmd->add_option("--out,-o", options.out, "Results file (JSON lines); default <spec's name>.results.jsonl here");
  cmd->add_option("--jobs,-j", options.jobs, "Runs at once on this machine, each in its own process")
      ->capture_default_str()
      ->check(integer_in(1, 1024, "processes"));
  cmd->add_option("--timeout", options.timeout, "Wall-clock seconds a run may take before it is killed (0: no limit)")
      ->capture_default_str()
      ->check(real_in(0, 1e9, "seconds"));
  add_stack_kib_option(*cmd, options.stack_kib);
  add_program_budget_option(*cmd, options.program_budget, "its run fails");
  cmd->add_flag("--quiet,-q", options.quiet, "No progress lines");
  cmd->add_option("--run", options.child_run, "(internal) run this one run here, report on descriptor 3")->group("");
  return cmd;
}

int sweep_command(const SweepOptions& options, const turtle::Registry& registry, const std::vector<std::string>& plugins) {
  const Spec spec = parse_spec(options.spec);
  const std::string out = options.out.empty() ? default_out(options.spec) : options.out;

  if (options.child_run) {
    if (::fcntl(3, F_GETFD) == -1 || *options.child_run >= spec.runs)
      throw BadInput("sweep --run is for turtlegas itself: it runs one run of the sweep and reports on descriptor 3");
    const std::string line = run_one(spec, *options.child_run, registry, server_options(options)).dump() + "\n";
    for (std::size_t done = 0; done < line.size();) {
      const ssize_t n = ::write(3, line.data() + done, line.size() - done);
      if (n <= 0) return exit_failure;
      done += static_cast<std::size_t>(n);
    }
    return exit_ok;
  }

  const int launched = launcher_size();
#ifdef TURTLEGAS_HAVE_MPI
  if (launched > 0) {
    MPI_Init(nullptr, nullptr);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    int rc = exit_ok;
    if (size == 1) {
      rc = run_local(options, registry, plugins, spec, out);
    } else if (rank == 0) {
      if (!options.quiet) spdlog::info("sweep: {} runs over {} MPI ranks (rank 0 hands them out)", spec.runs, size);
      rc = mpi_master(options, spec, out, size);
    } else {
      rc = mpi_worker(options, spec, registry);
    }
    MPI_Finalize();
    return rank == 0 ? rc : exit_ok;
  }
#else
  if (launched > 1)
    throw BadInput("sweep: this turtlegas was built without MPI, so under mpirun every rank would run the whole sweep; "
                   "install Open MPI (Debian: apt install libopenmpi-dev openmpi-bin), re-run cmake (it finds MPI) and "
                   "rebuild, or run on this machine with --jobs N");
  if (!options.quiet)
    spdlog::info("sweep: running on this machine with --jobs {} (this build has no MPI; for mpirun, install "
                 "libopenmpi-dev and rebuild: cmake finds it)",
                 options.jobs);
#endif
  return run_local(options, registry, plugins, spec, out);
}

}  // namespace turtlegas::apps
