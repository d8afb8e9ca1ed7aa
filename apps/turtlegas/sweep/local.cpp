// SPDX-License-Identifier: MIT
// `turtlegas sweep`: the runs as child processes of this machine, --jobs at once.
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <spdlog/spdlog.h>

#include "child_processes.hpp"
#include "cli_common.hpp"
#include "run_loop.hpp"
#include "signals.hpp"
#include "sweep/sweep.hpp"

namespace turtlegas::apps::sweep {

namespace {

constexpr std::string_view inputs_magic = "turtlegas-sweep-inputs/1\n";

}  // namespace

int share_inputs(const Inputs& inputs) {
  const int fd = ::memfd_create("turtlegas-sweep-inputs", 0);
  if (fd < 0) throw std::runtime_error(std::string("sweep: cannot hand the spec to its runs: ") + std::strerror(errno));
  const std::string text = std::string(inputs_magic) + std::to_string(inputs.spec.size()) + "\n" + inputs.spec + inputs.world;
  for (std::size_t done = 0; done < text.size();) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(std::string("sweep: cannot hand the spec to its runs: ") + std::strerror(errno));
    done += static_cast<std::size_t>(n);
  }
  // Above the descriptors a child is given (0-4, child_processes.hpp), and inherited: no O_CLOEXEC.
  const int high = ::fcntl(fd, F_DUPFD, 10);
  ::close(fd);
  if (high < 0) throw std::runtime_error(std::string("sweep: cannot hand the spec to its runs: ") + std::strerror(errno));
  return high;
}

Inputs read_inputs(int fd) {
  std::string text;
  char buf[65536];
  for (off_t at = 0;;) {  // pread: the children share the descriptor's offset
    const ssize_t n = ::pread(fd, buf, sizeof buf, at);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw BadInput("sweep --inputs-fd: cannot read descriptor " + std::to_string(fd) + ": " + std::strerror(errno));
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
    at += n;
  }
  const std::size_t eol = text.find('\n', inputs_magic.size());
  if (text.rfind(inputs_magic, 0) != 0 || eol == std::string::npos)
    throw BadInput("sweep --inputs-fd is for turtlegas itself: the spec and world its parent read");
  const std::size_t size = std::stoull(text.substr(inputs_magic.size(), eol - inputs_magic.size()));
  if (size > text.size() - eol - 1) throw BadInput("sweep --inputs-fd: the spec handed over is cut short");
  return {text.substr(eol + 1, size), text.substr(eol + 1 + size)};
}

std::vector<std::string> child_args(const SweepOptions& options, const std::vector<std::string>& plugins,
                                    const Spec& spec, std::size_t k, int inputs_fd) {
  std::vector<std::string> a = {"sweep", spec.file, "--run", std::to_string(k), "--inputs-fd", std::to_string(inputs_fd),
                                "--stack-kib", std::to_string(options.stack_kib), "--program-budget",
                                json(options.program_budget).dump()};
  for (const std::string& p : plugins) a.insert(a.end(), {"--plugin", p});
  return a;
}

std::optional<std::string> child_failure(const ChildResult& r, std::size_t k, std::string& line) {
  const json j = parse_or_discard(r.report);
  if (!r.timed_out && r.exited && r.exit_code == 0 && !j.is_discarded() && j.value("run", std::size_t(-1)) == k) {
    line = r.report;
    while (!line.empty() && line.back() == '\n') line.pop_back();
    return std::nullopt;
  }
  std::string why = r.timed_out ? "ran past --timeout" : r.how_it_ended();
  if (!r.err.empty()) why += "\n" + r.err;
  return why;
}

int run_local(const SweepOptions& options, const std::vector<std::string>& plugins, const Spec& spec,
              const std::string& out) {
  Results results;
  Journal journal(out, spec, results);
  if (const std::size_t n = collect_tasks(out, spec, results, journal); n > 0 && !options.quiet)
    spdlog::info("sweep: {} run(s) collected from the tasks' results in {}", n, tasks_dir(out));
  std::vector<std::size_t> pending;
  for (std::size_t k = 0; k < spec.runs; ++k)
    if (!results.count(k)) pending.push_back(k);
  if (!results.empty() && !options.quiet)
    spdlog::info("sweep: resuming: {} of {} runs already recorded in {}.partial", results.size(), spec.runs, out);
  // Every run is of the bytes read here, not of the files as they may be by the time it starts.
  const int inputs_fd = share_inputs(spec.bytes);
  std::vector<std::vector<std::string>> args;
  for (std::size_t k : pending) args.push_back(child_args(options, plugins, spec, k, inputs_fd));
  std::size_t failed = 0;
  StatusLine status(!options.quiet);
  auto on_done = [&](std::size_t i, ChildResult&& r) {
    const std::size_t k = pending[i];
    status.clear();
    if (r.stopped) return;  // killed at SIGINT or SIGTERM: left for the resumed sweep
    std::string line;
    if (std::optional<std::string> why = child_failure(r, k, line)) {
      ++failed;
      spdlog::error("sweep: run {} failed: {}", k, *why);
    } else {
      journal.record(line);
      results[k] = std::move(line);
      if (!options.quiet) spdlog::info("sweep: run {} done ({} of {})", k, results.size(), spec.runs);
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
  ::close(inputs_fd);
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
