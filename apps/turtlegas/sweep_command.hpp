// SPDX-License-Identifier: MIT
// `turtlegas sweep SPEC.json`: a grid of world-file overrides (JSON pointer -> values) x seeds,
// expanded into independent deterministic runs, their results gathered into one JSON-lines file
// and a summary table; resumable; on local cores (--jobs, a process per run) or under MPI
// (mpirun -n K turtlegas sweep ...: rank 0 hands out runs and gathers results). docs/sweeps.md.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "turtlegas/turtle/registry.hpp"

namespace turtlegas::apps {

struct SweepOptions {
  std::string spec;
  std::string out;             ///< the results file; default <spec's stem>.results.jsonl here
  std::size_t jobs = 1;        ///< runs at once, each in its own process (without MPI)
  double timeout = 0.0;        ///< wall-clock seconds a run may take; 0: no limit
  std::size_t stack_kib = 32;
  double program_budget = 2.0;
  bool quiet = false;          ///< no progress lines
  std::optional<std::size_t> child_run;  ///< hidden: run this one and report on descriptor 3
  std::optional<int> inputs_fd;          ///< hidden: the spec and world the parent read (sweep/sweep.hpp)
  /// Run one task of the sweep (sweep/tasks.cpp); default from SLURM_ARRAY_TASK_ID, PBS_ARRAY_INDEX
  /// or PBS_ARRAYID when set.
  std::optional<std::size_t> task_index;
  std::optional<std::size_t> tasks;  ///< how many tasks the runs are dealt into; default one per run
  bool gather = false;               ///< collect the tasks' results, run nothing
  bool resume = false;               ///< go on with a sweep begun before; refused when none was
};

CLI::App* add_sweep_command(CLI::App& app, SweepOptions& options);

/// Returns exit_ok when every run ended with a result, exit_failure when one did not (a crash, a
/// timeout), exit_bad_input for a bad spec or options.
int sweep_command(const SweepOptions& options, const turtle::Registry& registry, const std::vector<std::string>& plugins);

/// Whether this program was built with MPI (sweep can run under mpirun).
bool sweep_has_mpi();

}  // namespace turtlegas::apps
