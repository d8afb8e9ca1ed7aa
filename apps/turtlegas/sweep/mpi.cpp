// SPDX-License-Identifier: MIT
// `turtlegas sweep` under mpirun: rank 0 hands out runs one at a time and gathers their lines;
// without MPI in this build, the sweep runs on this machine and says how to get MPI.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include <unistd.h>

#include <spdlog/spdlog.h>

#ifdef TURTLEGAS_HAVE_MPI
#include <mpi.h>
#endif

#include "child_processes.hpp"
#include "cli_common.hpp"
#include "sweep/sweep.hpp"

namespace turtlegas::apps::sweep {
namespace {

using nlohmann::json;

/// Whether this process was started by mpirun (Open MPI, or a PMI launcher).
int launcher_size() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* s = std::getenv(v)) return std::atoi(s);
  return 0;
}

#ifdef TURTLEGAS_HAVE_MPI
constexpr int tag_ready = 1, tag_result = 2, tag_work = 3, tag_stop = 4;

/// Rank 0: hands out runs one at a time to whichever worker asks, gathers their lines.
int mpi_master(const SweepOptions& options, const Spec& spec, const std::string& out, int size) {
  Results results;
  Journal journal(out, spec, results);
  if (const std::size_t n = collect_tasks(out, spec, results, journal); n > 0 && !options.quiet)
    spdlog::info("sweep: {} run(s) collected from the tasks' results in {}", n, tasks_dir(out));
  std::vector<std::size_t> pending;
  for (std::size_t k = 0; k < spec.runs; ++k)
    if (!results.count(k)) pending.push_back(k);
  if (!results.empty() && !options.quiet)
    spdlog::info("sweep: resuming: {} of {} runs already recorded in {}.partial", results.size(), spec.runs, out);
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
  return finish(out, spec, results, journal, failed);
}

/// The bytes rank 0 read, sent to every rank (each read the files itself at its start, and one
/// edited meanwhile must not give one results file of two worlds).
Inputs g_rank0_inputs;

void share_rank0_inputs(int rank, const Spec& spec) {
  auto broadcast = [](std::string& s) {
    unsigned long long n = s.size();
    MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
    s.resize(static_cast<std::size_t>(n));
    for (std::size_t at = 0; at < s.size();) {  // MPI counts are int: in pieces under 2^30
      const int piece = static_cast<int>(std::min<std::size_t>(s.size() - at, std::size_t{1} << 30));
      MPI_Bcast(s.data() + at, piece, MPI_CHAR, 0, MPI_COMM_WORLD);
      at += static_cast<std::size_t>(piece);
    }
  };
  if (rank == 0) g_rank0_inputs = spec.bytes;
  broadcast(g_rank0_inputs.spec);
  broadcast(g_rank0_inputs.world);
}

Spec rank0_spec(const Spec& spec) { return parse_spec(spec.file, &g_rank0_inputs); }

/// Ranks 1 ... K-1: ask for a run, run it in a child process of this rank (as run_local does), send
/// its line or why it failed, until told to stop. A run that crashes (a plugin's segfault, an
/// abort) ends its child, named in the reply, not the rank: under mpirun a rank that dies takes
/// every rank with it, and each resume met the same run and died again.
int mpi_worker(const SweepOptions& options, const Spec& spec, const std::vector<std::string>& plugins) {
  const int inputs_fd = share_inputs(g_rank0_inputs);
  std::string msg;
  int tag = tag_ready;
  for (;;) {
    MPI_Send(msg.data(), static_cast<int>(msg.size()), MPI_CHAR, 0, tag, MPI_COMM_WORLD);
    std::uint64_t k = 0;
    MPI_Status st;
    MPI_Recv(&k, 1, MPI_UINT64_T, 0, MPI_ANY_TAG, MPI_COMM_WORLD, &st);
    if (st.MPI_TAG == tag_stop) break;
    const std::size_t run = static_cast<std::size_t>(k);
    msg.clear();
    try {
      run_children({child_args(options, plugins, spec, run, inputs_fd)}, 1, options.timeout,
                   {[&](std::size_t, ChildResult&& r) {
                      std::string line;
                      if (std::optional<std::string> why = child_failure(r, run, line))
                        msg = json{{"run", k}, {"error", *why}}.dump();
                      else
                        msg = std::move(line);
                    },
                    nullptr});
    } catch (const std::exception& e) {
      msg = json{{"run", k}, {"error", e.what()}}.dump();
    }
    if (msg.empty()) msg = json{{"run", k}, {"error", "stopped before it ended"}}.dump();
    tag = tag_result;
  }
  ::close(inputs_fd);
  return exit_ok;
}
#endif

}  // namespace

int run_launched(const SweepOptions& options, const turtle::Registry& registry, const std::vector<std::string>& plugins,
                 const Spec& spec, const std::string& out) {
  const int launched = launcher_size();
#ifdef TURTLEGAS_HAVE_MPI
  if (launched > 0) {
    MPI_Init(nullptr, nullptr);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    int rc = exit_ok;
    if (size > 1) share_rank0_inputs(rank, spec);
    if (size == 1) {
      rc = run_local(options, plugins, spec, out);
    } else if (rank == 0) {
      if (!options.quiet) spdlog::info("sweep: {} runs over {} MPI ranks (rank 0 hands them out)", spec.runs, size);
      rc = mpi_master(options, spec, out, size);
    } else {
      rc = mpi_worker(options, rank0_spec(spec), plugins);
      (void)registry;
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
  (void)registry;
#endif
  return run_local(options, plugins, spec, out);
}

}  // namespace turtlegas::apps::sweep

