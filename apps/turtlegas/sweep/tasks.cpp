// SPDX-License-Identifier: MIT
// `turtlegas sweep --task-index I`: one task of a sweep, for job arrays (Slurm, PBS), GNU parallel
// or any scheduler that starts independent processes (docs/scaling.md). Task I of N runs the runs
// k = I, I + N, I + 2N, ... in this process and writes each result to a file of its own,
// <out>.tasks/run-K.json (written under a temporary name and renamed: whole or absent), which
// `sweep --gather` and the sweep's resuming collect into the results file. Idempotent: a run whose
// file holds a result of this spec is not run again, so a task may be resubmitted or run twice.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include <spdlog/spdlog.h>

#include "cli_common.hpp"
#include "sweep/sweep.hpp"

namespace turtlegas::apps::sweep {
namespace {

namespace fs = std::filesystem;

std::string run_file(const std::string& out, std::size_t k) {
  return (fs::path(tasks_dir(out)) / ("run-" + std::to_string(k) + ".json")).string();
}

/// The result line in run k's file when it is one of this spec's run k; else empty.
std::string read_result(const std::string& out, const Spec& spec, std::size_t k, const std::string& fp) {
  std::ifstream in(run_file(out, k));
  std::string header, line;
  if (!in || !std::getline(in, header) || !std::getline(in, line)) return {};
  const json h = parse_or_discard(header), j = parse_or_discard(line);
  if (h.is_discarded() || !h.is_object() || h.value("fingerprint", "") != fp) return {};
  if (j.is_discarded() || j.value("run", json()) != json(k) || !is_result_of(spec, k, j)) return {};
  return line;
}

/// Writes run k's file: a header with the spec's fingerprint, then the result line; under a
/// temporary name of this process, renamed over the target, so a reader sees it whole or not at all.
void write_result(const std::string& out, std::size_t k, const std::string& fp, const std::string& file,
                  const std::string& line) {
  const std::string target = run_file(out, k);
  const std::string tmp = target + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream f(tmp, std::ios::trunc);
    f << json{{"fingerprint", fp}, {"spec", file}, {"run", k}}.dump() << '\n' << line << '\n';
    f.flush();
    if (!f) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error(target + ": cannot write run " + std::to_string(k) + "'s result (a full disk?)");
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error(target + ": cannot write run " + std::to_string(k) + "'s result: " + ec.message());
  }
}

}  // namespace

std::string tasks_dir(const std::string& out) { return out + ".tasks"; }

std::size_t task_count(const Spec& spec, std::optional<std::size_t> tasks) {
  return tasks ? *tasks : spec.runs;
}

int run_task(const SweepOptions& options, const turtle::Registry& registry, const Spec& spec, const std::string& out,
             std::size_t index, const std::string& from) {
  const std::size_t tasks = task_count(spec, options.tasks);
  if (tasks == 0 || tasks > spec.runs)
    throw BadInput("sweep --tasks " + std::to_string(tasks) + ": a sweep of " + std::to_string(spec.runs) +
                   " runs has 1 to " + std::to_string(spec.runs) + " tasks");
  if (index >= tasks)
    throw BadInput("sweep: task index " + std::to_string(index) + from + " is past the last task: " + spec.file +
                   " has " + std::to_string(tasks) + " tasks, 0 to " + std::to_string(tasks - 1) +
                   (options.tasks ? "" : " (one per run; --tasks N groups them)") +
                   "; number a job array from 0 (Slurm: --array=0-" + std::to_string(tasks - 1) + ")");
  std::error_code ec;
  fs::create_directories(tasks_dir(out), ec);
  if (ec) throw BadInput(tasks_dir(out) + ": cannot make the folder of the sweep's task results: " + ec.message());
  const std::string fp = fingerprint(spec);
  std::size_t ran = 0, had = 0;
  for (std::size_t k = index; k < spec.runs; k += tasks) {
    if (!read_result(out, spec, k, fp).empty()) {
      ++had;
      continue;
    }
    const std::string line = run_one(spec, k, registry, server_options(options)).dump();
    write_result(out, k, fp, spec.file, line);
    ++ran;
  }
  if (!options.quiet)
    spdlog::info("sweep: task {} of {}{}: {} run(s) run, {} had a result already; in {}", index, tasks, from, ran, had,
                 tasks_dir(out));
  return exit_ok;
}

std::size_t collect_tasks(const std::string& out, const Spec& spec, Results& results, Journal& journal) {
  if (!fs::is_directory(tasks_dir(out))) return 0;
  const std::string fp = fingerprint(spec);
  std::size_t n = 0;
  for (std::size_t k = 0; k < spec.runs; ++k) {
    if (results.count(k)) continue;
    std::string line = read_result(out, spec, k, fp);
    if (line.empty()) continue;
    journal.record(line);
    results[k] = std::move(line);
    ++n;
  }
  return n;
}

void remove_tasks(const std::string& out) {
  std::error_code ec;
  fs::remove_all(tasks_dir(out), ec);
}

int gather(const SweepOptions& options, const Spec& spec, const std::string& out) {
  Results results;
  Journal journal(out, spec, results);
  const std::size_t journaled = results.size();
  const std::size_t collected = collect_tasks(out, spec, results, journal);
  if (!options.quiet)
    spdlog::info("sweep --gather: {} run(s) from {}, {} from {}.partial, of {}", collected, tasks_dir(out), journaled,
                 out, spec.runs);
  if (results.size() == spec.runs) return finish(out, spec, results, journal, 0);
  const std::size_t tasks = task_count(spec, options.tasks);
  std::string missing;
  std::size_t listed = 0;
  for (std::size_t k = 0; k < spec.runs; ++k) {
    if (results.count(k)) continue;
    if (listed++ < 20) missing += (missing.empty() ? "" : ", ") + std::to_string(k) + " (task " + std::to_string(k % tasks) + ")";
  }
  std::fputs(summary_table(spec, results).c_str(), stdout);
  spdlog::error("sweep --gather: {} of {} runs have no result yet: run {}{}; run those tasks (--task-index), or the "
                "sweep without --gather to run them here",
                spec.runs - results.size(), spec.runs, missing, listed > 20 ? ", ..." : "");
  return exit_failure;
}

}  // namespace turtlegas::apps::sweep
