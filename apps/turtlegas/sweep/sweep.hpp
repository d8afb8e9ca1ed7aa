// SPDX-License-Identifier: MIT
// The parts of `turtlegas sweep` (sweep_command.hpp, docs/sweeps.md), one role per file:
//   spec.cpp     the spec: read, checked, expanded into runs (grid point x seed)
//   run.cpp      one run, in this process: its result line
//   journal.cpp  the journal beside the results (<out>.partial) that makes a sweep resumable
//   results.cpp  the summary table and the results file
//   local.cpp    the runs as child processes of this machine (--jobs)
//   mpi.cpp      the runs over MPI ranks (mpirun), or why not
//   tasks.cpp    one task of a sweep (--task-index, job arrays) and gathering the tasks' results
// Private to the sweep command: nothing here is seen by the other commands.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "child_processes.hpp"
#include "turtlegas/formats/observables.hpp"
#include "sweep_command.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::apps::sweep {

using nlohmann::json;

constexpr std::size_t max_runs = 10'000'000;

/// The bytes a sweep read: its spec and its world file, as they were when it began. Its runs (child
/// processes, MPI ranks) are handed these rather than read the files again, so that a file edited
/// while the sweep goes on cannot give one results file of two worlds.
struct Inputs {
  std::string spec;
  std::string world;
};

/// A sweep specification (docs/sweeps.md).
struct Spec {
  Inputs bytes;             ///< the files as read
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
  /// The spec's "observe": each run measures the gas (formats/observables.hpp) and its line carries
  /// "observables": the summary and the species, or (observe.full) the whole measurement.
  std::optional<formats::ObserveOptions> observe;
  bool observe_full = false;
};

/// Reads and checks a spec and its world file (or, given, the bytes the sweep read at its start);
/// BadInput naming the key for one that is not right.
Spec parse_spec(const std::string& file, const Inputs* given = nullptr);

/// Hands `inputs` to child processes: a memory file whose descriptor (returned, >= 10) the children
/// inherit. read_inputs(fd) in the child reads it back.
int share_inputs(const Inputs& inputs);
/// The inputs a parent shared (share_inputs); BadInput when the descriptor holds none.
Inputs read_inputs(int fd);

/// Run k's grid point (one value index per axis, the first axis slowest) and seed.
std::pair<std::vector<std::size_t>, std::uint64_t> decompose(const Spec& spec, std::size_t k);
/// Run k's grid point as world-file overrides: JSON pointer -> value.
json overrides_of(const Spec& spec, const std::vector<std::size_t>& idx);

/// The options of every run of the sweep.
turtle::ServerOptions server_options(const SweepOptions& o);
/// Runs run k in this process: its result line (without a newline). Deterministic: no wall-clock
/// figures in it.
json run_one(const Spec& spec, std::size_t k, const turtle::Registry& registry, const turtle::ServerOptions& base);

/// The results so far: run index -> its line.
using Results = std::map<std::size_t, std::string>;

/// The spec's and its world's fingerprint: a journal of another spec or world is not resumed.
/// json::parse(text, nullptr, false), with a text nested too deep (turtle::json_too_deep) discarded
/// as invalid JSON is: a journal line or a child's report that no run wrote.
json parse_or_discard(const std::string& text);

std::string fingerprint(const Spec& spec);
/// Whether j is a result line of run k as run_one writes it: k's seed and overrides, and stats.
bool is_result_of(const Spec& spec, std::size_t k, const json& j);

/// The journal beside the results (<out>.partial): a header line with the spec's fingerprint,
/// then one line per finished run, appended as each ends. A line cut short by a kill is dropped.
class Journal {
 public:
  /// Reads the runs a journal of this spec already holds into `results` and rewrites it whole
  /// (a cut line gone); BadInput for a journal of another spec or world.
  Journal(const std::string& out, const Spec& spec, Results& results);
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;
  ~Journal();
  /// Appends a run's line; std::runtime_error saying what failed and where when it cannot be
  /// written whole (a full disk), the journal then holding the lines that were.
  void record(const std::string& line);
  /// The sweep is done: the journal goes.
  void remove();

 private:
  std::string path_;
  int fd_ = -1;
  std::size_t recorded_ = 0;  ///< runs in the journal
};

/// Per grid point, the mean and 95 % t-interval of each summary pointer over the seeds.
std::string summary_table(const Spec& spec, const Results& results);
/// <spec's stem>.results.jsonl, here.
std::string default_out(const std::string& spec);
/// What is wrong with each summary pointer that no result line has as a number: in none (misspelt;
/// parse_spec names most before any run), or at an object, array or string in all.
std::vector<std::string> summary_not_found(const Spec& spec, const Results& results);
/// The end of a sweep: the summary table, and the results file when every run has a result (the
/// journal then removed). exit_ok; exit_failure when runs are missing; exit_bad_input when a
/// summary pointer is in no result line (the results are written all the same).
int finish(const std::string& out, const Spec& spec, Results& results, Journal& journal, std::size_t failed);

/// The command line of the child that runs run k (`sweep SPEC --run k --inputs-fd FD ...`).
std::vector<std::string> child_args(const SweepOptions& options, const std::vector<std::string>& plugins,
                                    const Spec& spec, std::size_t k, int inputs_fd);
/// Why the child that ran run k failed (a crash, a timeout, no report: its stderr appended), or
/// nothing when it reported run k; then `line` is its result line.
std::optional<std::string> child_failure(const ChildResult& r, std::size_t k, std::string& line);
/// Runs the sweep's runs as child processes of this machine, --jobs at once.
int run_local(const SweepOptions& options, const std::vector<std::string>& plugins, const Spec& spec,
              const std::string& out);
/// Runs the sweep under mpirun when this process was started by it (and this build has MPI), else
/// on this machine (run_local).
int run_launched(const SweepOptions& options, const turtle::Registry& registry, const std::vector<std::string>& plugins,
                 const Spec& spec, const std::string& out);

/// The folder of the tasks' results beside the results file: <out>.tasks.
std::string tasks_dir(const std::string& out);
/// How many tasks a sweep has: --tasks, else one per run.
std::size_t task_count(const Spec& spec, std::optional<std::size_t> tasks);
/// Runs task `index` (its runs k = index mod the task count) in this process, each result to a file
/// of its own in tasks_dir(out); a run that has one already is not run again. `from` says where the
/// index came from (" (SLURM_ARRAY_TASK_ID)"), for messages.
int run_task(const SweepOptions& options, const turtle::Registry& registry, const Spec& spec, const std::string& out,
             std::size_t index, const std::string& from);
/// Adds the tasks' results that `results` lacks (valid ones of this spec), each recorded in the
/// journal; how many.
std::size_t collect_tasks(const std::string& out, const Spec& spec, Results& results, Journal& journal);
/// The results file is whole: the tasks' folder goes.
void remove_tasks(const std::string& out);
/// `sweep --gather`: the journal's and the tasks' results, the results file when every run has one
/// (exit_ok), else the runs and tasks missing (exit_failure). Runs nothing.
int gather(const SweepOptions& options, const Spec& spec, const std::string& out);

}  // namespace turtlegas::apps::sweep
