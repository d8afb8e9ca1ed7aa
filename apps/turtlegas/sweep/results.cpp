// SPDX-License-Identifier: MIT
// `turtlegas sweep`: the summary table and the results file.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "cli_common.hpp"
#include "output_file.hpp"
#include "sweep/sweep.hpp"
#include "turtlegas/world/tag_tournament.hpp"

namespace turtlegas::apps::sweep {
namespace {

namespace fs = std::filesystem;

std::string fixed(double v, int digits) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
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
}  // namespace

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
std::string default_out(const std::string& spec) {
  return fs::path(spec).stem().string() + ".results.jsonl";
}
std::vector<std::string> summary_not_found(const Spec& spec, const Results& results) {
  std::vector<std::string> missing;
  for (const std::string& p : spec.summary) {
    const json::json_pointer ptr(p);
    bool found = false;
    std::string kind;
    for (auto it = results.begin(); it != results.end() && !found; ++it) {
      const json j = json::parse(it->second, nullptr, false);
      if (j.is_discarded() || !j.contains(ptr)) continue;
      found = j.at(ptr).is_number();
      if (!found) kind = j.at(ptr).type_name();
    }
    // A pointer at an object or a string is as useless in the table as a misspelt one.
    if (!found)
      missing.push_back("\"" + p + "\" " +
                        (kind.empty() ? "is in no result line (misspelt? a line has /run, /seed, /overrides, /stats/... as "
                                        "docs/sweeps.md lists, /tag with a game, /expect with an expect list, "
                                        "/observables with observe)"
                                      : "points at " + std::string(kind == "object" || kind == "array" ? "an " : "a ") +
                                            kind + " in the result lines, not a number: name one inside it (\"" + p +
                                            "/...\")"));
  }
  return missing;
}

int finish(const std::string& out, const Spec& spec, Results& results, Journal& journal, std::size_t failed) {
  std::fputs(summary_table(spec, results).c_str(), stdout);
  // A summary pointer that no result line has is a misspelling, not a column of "-".
  const std::vector<std::string> missing = results.empty() ? std::vector<std::string>{} : summary_not_found(spec, results);
  for (const std::string& m : missing) spdlog::error("{}: /summary: {}", spec.file, m);
  if (results.size() == spec.runs) {
    write_results(out, spec, results);
    journal.remove();
    remove_tasks(out);
    std::printf("%zu runs; results in %s\n", spec.runs, out.c_str());
    return missing.empty() ? exit_ok : exit_bad_input;
  }
  std::printf("%zu of %zu runs have results (%zu failed); run the same command again to retry the rest\n",
              results.size(), spec.runs, failed);
  return exit_failure;
}

}  // namespace turtlegas::apps::sweep
