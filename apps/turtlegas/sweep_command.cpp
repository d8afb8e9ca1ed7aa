// SPDX-License-Identifier: MIT
// `turtlegas sweep`: its command line, and the child's side of a run (sweep --run K). The spec, the
// runs, the journal, the results and the schedulers are in sweep/ (sweep/sweep.hpp lists them).
#include "sweep_command.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "output_file.hpp"
#include "signals.hpp"
#include "sweep/sweep.hpp"

namespace turtlegas::apps {

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
  cmd->add_option("--task-index", options.task_index,
                  "Run only this task of the sweep (0-based; its runs k with k mod --tasks = I), results into "
                  "<out>.tasks/; default $SLURM_ARRAY_TASK_ID, $PBS_ARRAY_INDEX or $PBS_ARRAYID when set "
                  "(docs/scaling.md)");
  cmd->add_option("--tasks", options.tasks, "How many tasks the runs are dealt into (default: one per run)")
      ->check(integer_in(1, 10000000, "tasks"));
  cmd->add_flag("--gather", options.gather,
                "Collect the tasks' results (and the journal's) into the results file; run nothing, and name the "
                "runs still missing");
  cmd->add_flag("--resume", options.resume,
                "Go on with a sweep begun before (its journal, its tasks' results), running only the missing runs; "
                "refused when there is none (the same command without it resumes too, or starts afresh)");
  cmd->add_option("--run", options.child_run, "(internal) run this one run here, report on descriptor 3")->group("");
  cmd->add_option("--inputs-fd", options.inputs_fd, "(internal) the spec and world the parent read, on this descriptor")
      ->group("");
  return cmd;
}
int sweep_command(const SweepOptions& options, const turtle::Registry& registry, const std::vector<std::string>& plugins) {
  if (options.child_run) {
    // The spec and world the parent read, not the files as they are now (sweep/sweep.hpp, Inputs).
    if (::fcntl(3, F_GETFD) == -1 || !options.inputs_fd || ::fcntl(*options.inputs_fd, F_GETFD) == -1)
      throw BadInput("sweep --run is for turtlegas itself: it runs one run of the sweep and reports on descriptor 3");
    const sweep::Inputs given = sweep::read_inputs(*options.inputs_fd);
    const sweep::Spec spec = sweep::parse_spec(options.spec, &given);
    if (*options.child_run >= spec.runs)
      throw BadInput("sweep --run is for turtlegas itself: it runs one run of the sweep and reports on descriptor 3");
    // A crash names the run, the turtle and its controller, as `run` does (the parent shows it).
    install_crash_report(spec.world_file + " (sweep run " + std::to_string(*options.child_run) + ")");
    const std::string line = sweep::run_one(spec, *options.child_run, registry, sweep::server_options(options)).dump() + "\n";
    for (std::size_t done = 0; done < line.size();) {
      const ssize_t n = ::write(3, line.data() + done, line.size() - done);
      if (n <= 0) return exit_failure;
      done += static_cast<std::size_t>(n);
    }
    return exit_ok;
  }

  const sweep::Spec spec = sweep::parse_spec(options.spec);
  const std::string out = options.out.empty() ? sweep::default_out(options.spec) : options.out;
  // The results and the journal beside them must not be the spec or the world they come from.
  std::vector<NamedPath> inputs{{spec.file, "the sweep spec"}, {spec.world_file, "the world file"}};
  for (const std::string& p : plugins) inputs.push_back({p, "--plugin"});
  check_outputs({{out, "--out"}, {out + ".partial", "--out's journal (" + out + ".partial)"}}, inputs);

  if (options.gather && options.task_index)
    throw BadInput("sweep --gather collects the tasks' results; --task-index runs one task: give one of the two");
  // A job array's task: its index from the option, else from the scheduler's variable.
  std::optional<std::size_t> index = options.task_index;
  std::string from;
  if (!index && !options.gather && !options.resume) {
    for (const char* name : {"SLURM_ARRAY_TASK_ID", "PBS_ARRAY_INDEX", "PBS_ARRAYID"}) {
      const char* v = std::getenv(name);
      if (!v || !*v) continue;
      char* end = nullptr;
      const unsigned long long i = std::strtoull(v, &end, 10);
      if (*end != '\0' || v[0] == '-')
        throw BadInput(std::string("sweep: ") + name + "=" + v + " is not a task index (an integer >= 0); give "
                       "--task-index I, or unset " + name + " to run the whole sweep here");
      index = static_cast<std::size_t>(i);
      from = std::string(" (") + name + ")";
      break;
    }
  }
  if (index) return sweep::run_task(options, registry, spec, out, *index, from);
  if (options.gather) return sweep::gather(options, spec, out);
  if (options.resume && !std::filesystem::exists(out + ".partial") && !std::filesystem::is_directory(sweep::tasks_dir(out)))
    throw BadInput("sweep --resume: nothing to go on with: no journal " + out + ".partial and no task results in " +
                   sweep::tasks_dir(out) + " (another --out? leave out --resume to start the sweep)");
  return sweep::run_launched(options, registry, plugins, spec, out);
}

}  // namespace turtlegas::apps
