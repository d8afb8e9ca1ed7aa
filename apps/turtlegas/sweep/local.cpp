// SPDX-License-Identifier: MIT
// `turtlegas sweep`: the runs as child processes of this machine, --jobs at once.
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "child_processes.hpp"
#include "cli_common.hpp"
#include "run_loop.hpp"
#include "signals.hpp"
#include "sweep/sweep.hpp"

namespace turtlegas::apps::sweep {

int run_local(const SweepOptions& options, const std::vector<std::string>& plugins, const Spec& spec,
              const std::string& out) {
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
    const json j = json::parse(r.report, nullptr, false);
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
  return finish(out, spec, results, journal, failed);
}
}  // namespace turtlegas::apps::sweep
