// SPDX-License-Identifier: MIT
// `turtlegas sweep`: the journal that makes a sweep resumable. Every write is checked: a failed one
// (a full disk) says what failed and where, and leaves the journal with the lines that were whole.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <spdlog/spdlog.h>

#include "checkpoint.hpp"
#include "cli_common.hpp"
#include "sweep/sweep.hpp"
#include "turtlegas/turtle/json_depth.hpp"

namespace turtlegas::apps::sweep {

json parse_or_discard(const std::string& text) {
  if (turtle::json_too_deep(text)) return json(json::value_t::discarded);
  return json::parse(text, nullptr, false);
}

namespace {

namespace fs = std::filesystem;

/// Writes all of `text` at the end of fd; on failure, strerror (the file keeps what it had).
std::string append_all(int fd, const std::string& text) {
  const off_t before = ::lseek(fd, 0, SEEK_END);
  for (std::size_t done = 0; done < text.size();) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = n < 0 ? std::strerror(errno) : "the write made no progress";
      if (before >= 0 && ::ftruncate(fd, before) != 0) return why + " (and a part of the line may be left)";
      return why;
    }
    done += static_cast<std::size_t>(n);
  }
  return {};
}

}  // namespace

bool is_result_of(const Spec& spec, std::size_t k, const json& j) {
  const auto [idx, seed] = decompose(spec, k);
  return j.is_object() && j.value("seed", json()) == json(seed) && j.value("overrides", json()) == overrides_of(spec, idx) &&
         j.contains("stats") && j["stats"].is_object();
}

std::string fingerprint(const Spec& spec) {
  char b[32];
  std::snprintf(b, sizeof b, "%016llx",
                static_cast<unsigned long long>(fnv1a64(spec.text.dump() + "\n" + spec.world.dump())));
  return b;
}

Journal::Journal(const std::string& out, const Spec& spec, Results& results) : path_(out + ".partial") {
  const std::string fp = fingerprint(spec);
  std::vector<std::string> good;
  std::size_t untrusted = 0;
  if (fs::exists(path_)) {
    // The header is written twice (lines 1 and 2): one damaged header line does not cost the runs.
    std::ifstream in(path_);
    std::string line;
    std::size_t n = 0;
    bool any = false, ours = false, theirs = false;
    std::vector<std::pair<std::size_t, std::string>> runs;
    while (std::getline(in, line)) {
      any = true;
      const json j = parse_or_discard(line);
      if (++n <= 2 && (n == 1 || j.is_discarded() || j.contains("fingerprint"))) {
        if (!j.is_discarded() && j.contains("fingerprint")) (j.value("fingerprint", "") == fp ? ours : theirs) = true;
        continue;
      }
      if (j.is_discarded() || !j.contains("run") || !j["run"].is_number_unsigned() || in.eof()) continue;
      const std::size_t k = j["run"].get<std::size_t>();
      if (k >= spec.runs) continue;
      if (!is_result_of(spec, k, j)) {
        ++untrusted;
        continue;
      }
      runs.emplace_back(k, line);
    }
    if (any && (theirs || !ours))
      throw BadInput(path_ + (theirs ? ": a partial sweep of another spec or world"
                                     : ": its header (the spec's fingerprint) is damaged, so its runs cannot be told "
                                       "from another spec's") +
                     " (delete it, or choose another --out)");
    for (auto& [k, l] : runs)
      if (!results.count(k)) {
        results[k] = l;
        good.push_back(std::move(l));
      }
  }
  if (untrusted > 0)
    spdlog::warn("{}: {} line(s) are not a result of this sweep's run they name (its seed, overrides and stats); "
                 "those runs run again",
                 path_, untrusted);
  // Rewritten whole (a cut line gone) under another name and renamed, then appended to.
  const std::string tmp = path_ + ".tmp";
  const std::string header = json{{"fingerprint", fp}, {"spec", spec.file}}.dump() + "\n";
  std::string text = header + header;
  for (const std::string& l : good) text += l + "\n";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw BadInput(path_ + ": cannot write the sweep's journal here (" + std::strerror(errno) + ")");
  std::string why = append_all(fd, text);
  if (::close(fd) != 0 && why.empty()) why = std::strerror(errno);
  std::error_code ec;
  if (why.empty()) fs::rename(tmp, path_, ec);
  if (!why.empty() || ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error(path_ + ": cannot write the sweep's journal: " + (why.empty() ? ec.message() : why) +
                             (fs::exists(path_) ? "; it is left as it was" : ""));
  }
  recorded_ = good.size();
  fd_ = ::open(path_.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd_ < 0) throw std::runtime_error(path_ + ": cannot append to the sweep's journal: " + std::strerror(errno));
}

Journal::~Journal() {
  if (fd_ >= 0) ::close(fd_);
}

void Journal::record(const std::string& line) {
  const std::string why = append_all(fd_, line + "\n");
  if (!why.empty())
    throw std::runtime_error(path_ + ": cannot append a finished run to the sweep's journal: " + why + "; the " +
                             std::to_string(recorded_) +
                             " runs recorded before are kept whole there: make room and run the same command again "
                             "to go on");
  ++recorded_;
}

void Journal::remove() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  std::error_code ec;
  fs::remove(path_, ec);
}

}  // namespace turtlegas::apps::sweep
