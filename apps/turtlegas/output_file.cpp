// SPDX-License-Identifier: MIT
#include "output_file.hpp"

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <atomic>
#include <iostream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

#include <spdlog/spdlog.h>

#include "cli_common.hpp"

namespace turtlegas::apps {

namespace fs = std::filesystem;

namespace {

// The temporary files being written, for remove_temporaries(): fixed slots of plain pointers, so
// that a signal handler can walk them without locks or allocation.
std::array<std::atomic<const char*>, 32> g_temporaries{};
std::atomic<bool> g_committed{false};  // any_output_committed()

void register_temporary(const char* path) {
  for (auto& slot : g_temporaries) {
    const char* expected = nullptr;
    if (slot.compare_exchange_strong(expected, path)) return;
  }
  // More than 32 outputs at once: the extra ones are still removed by their destructors.
}

void unregister_temporary(const char* path) {
  for (auto& slot : g_temporaries) {
    const char* expected = path;
    if (slot.compare_exchange_strong(expected, nullptr)) return;
  }
}

// The temporaries worth keeping when a busy loop ends the process (keep_on_busy_loop()), with the
// targets they replace: the same kind of slots.
struct Kept {
  std::atomic<const char*> tmp{nullptr};
  std::atomic<const char*> target{nullptr};
};
std::array<Kept, 8> g_kept{};

void unkeep(const char* tmp) {
  for (Kept& k : g_kept)
    if (k.tmp.load() == tmp) k.target.store(nullptr), k.tmp.store(nullptr);
}

/// Follows symlinks (a chain of at most 40, as the kernel does) to the path they end at, which
/// may not exist yet (a dangling link names the file to create).
fs::path follow_links(fs::path p, std::string_view option) {
  for (int hops = 0; hops < 40; ++hops) {
    std::error_code ec;
    if (!fs::is_symlink(fs::symlink_status(p, ec))) return p;
    const fs::path to = fs::read_symlink(p, ec);
    if (ec) return p;
    p = to.is_absolute() ? to : p.parent_path() / to;
  }
  throw BadInput(std::string(option) + ": '" + p.string() + "': too many levels of symbolic links");
}

/// The file at p, identified by device and inode (following links), if it exists.
bool same_file(const std::string& a, const std::string& b) {
  struct stat sa{}, sb{};
  if (::stat(a.c_str(), &sa) == 0 && ::stat(b.c_str(), &sb) == 0) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  // Not there yet (a new output): the same name once links and dots are resolved.
  std::error_code ec1, ec2;
  const fs::path ca = fs::weakly_canonical(a, ec1), cb = fs::weakly_canonical(b, ec2);
  return !ec1 && !ec2 && ca == cb;
}

}  // namespace

namespace detail {

CheckedFileBuf::int_type CheckedFileBuf::overflow(int_type c) {
  errno = 0;
  const int_type r = std::filebuf::overflow(c);
  if (traits_type::eq_int_type(r, traits_type::eof()) && error == 0) error = errno != 0 ? errno : EIO;
  return r;
}

std::streamsize CheckedFileBuf::xsputn(const char* s, std::streamsize n) {
  errno = 0;
  const std::streamsize r = std::filebuf::xsputn(s, n);
  if (r < n && error == 0) error = errno != 0 ? errno : EIO;
  return r;
}

int CheckedFileBuf::sync() {
  errno = 0;
  const int r = std::filebuf::sync();
  if (r != 0 && error == 0) error = errno != 0 ? errno : EIO;
  return r;
}

}  // namespace detail

namespace {

/// The temporaries `.NAME.tmp-PID` beside `target` left by runs that were killed (SIGKILL, a power
/// cut: nothing of theirs ran to remove them) and whose process is gone: an empty one is removed, one
/// with something in it (an event log up to its last flushed line) is renamed to NAME.killed-PID,
/// where a user sees it, and named. Before, they piled up hidden.
void tidy_killed_temporaries(const fs::path& dir, const fs::path& target, const std::string& opt) {
  const std::string prefix = "." + target.filename().string() + ".tmp-";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(digits));
    if (pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;  // its run may still be going
    std::error_code e;
    if (!it->is_regular_file(e)) continue;
    if (fs::file_size(it->path(), e) == 0) {
      fs::remove(it->path(), e);
      continue;
    }
    const fs::path kept = target.string() + ".killed-" + digits;
    fs::rename(it->path(), kept, e);
    if (!e)
      spdlog::warn("{}: a run that was killed (process {}, gone) left what it had written of {} hidden in {}; kept as {}",
                   opt, digits, target.filename().string(), name, kept.string());
  }
}

}  // namespace

OutputFile::OutputFile(const std::string& path, std::string_view option, Write how) : path_(path), option_(option) {
  const std::string opt(option);
  if (path == "-") {
    kind_ = Kind::standard_output;
    return;
  }
  if (path.empty()) throw BadInput(opt + ": needs a file name (or - for standard output)");
  target_ = follow_links(path, option);
  std::error_code ec;
  const fs::file_status st = fs::status(target_, ec);
  if (fs::is_directory(st)) throw BadInput(opt + ": '" + path + "' is a directory; give a file name");
  if (fs::exists(st) && !fs::is_regular_file(st)) {
    // A terminal, a pipe, a device: there is nothing to replace, and renaming over it would put a
    // regular file in its place (as root, over /dev/stdout). Written as it goes.
    kind_ = Kind::direct;
    buf_.open(target_, std::ios::binary | std::ios::out);
    if (!buf_.is_open()) throw BadInput(opt + ": cannot open '" + path + "' for writing; check its permissions");
    return;
  }
  const fs::path dir = target_.parent_path().empty() ? fs::path(".") : target_.parent_path();
  if (!fs::is_directory(dir, ec))
    throw BadInput(opt + ": directory '" + dir.string() + "' does not exist; create it first");
  if (how == Write::growing) {
    // Not registered as a temporary: what a killed run recorded stays readable (docs/recording.md).
    kind_ = Kind::growing;
    tmp_ = target_.string() + ".partial";
    buf_.open(tmp_, std::ios::binary | std::ios::out | std::ios::trunc);
    if (!buf_.is_open()) throw BadInput(opt + ": cannot write '" + tmp_.string() + "'; check the permissions of its directory");
    if (fs::is_regular_file(st)) fs::permissions(tmp_, st.permissions(), ec);
    return;
  }
  tidy_killed_temporaries(dir, target_, opt);
  tmp_ = dir / ("." + target_.filename().string() + ".tmp-" + std::to_string(::getpid()));
  buf_.open(tmp_, std::ios::binary | std::ios::out | std::ios::trunc);
  if (!buf_.is_open()) throw BadInput(opt + ": cannot write in '" + dir.string() + "'; check its permissions");
  register_temporary(tmp_.c_str());
  // The replacement keeps the permissions of the file it replaces.
  if (fs::is_regular_file(st)) fs::permissions(tmp_, st.permissions(), ec);
}

OutputFile::~OutputFile() {
  if (kind_ != Kind::replaced || committed_) return;  // a growing file's .partial stays
  unkeep(tmp_.c_str());
  unregister_temporary(tmp_.c_str());
  buf_.close();
  std::error_code ec;
  fs::remove(tmp_, ec);
}

std::string OutputFile::failure() const {
  if (buf_.error != 0) return std::strerror(buf_.error);
  return out_.fail() && kind_ != Kind::standard_output ? "a write failed" : "";
}

std::string OutputFile::close() {
  out_.flush();
  if (!buf_.close()) out_.setstate(std::ios::failbit);
  return failure();
}

std::ostream& OutputFile::stream() { return kind_ == Kind::standard_output ? std::cout : out_; }

void OutputFile::flush() { stream().flush(); }

void OutputFile::keep_on_busy_loop() {
  if (kind_ != Kind::replaced) return;  // written in place: kept anyway
  for (Kept& k : g_kept) {
    const char* expected = nullptr;
    if (k.tmp.compare_exchange_strong(expected, tmp_.c_str())) {
      k.target.store(target_.c_str());
      return;
    }
  }
}

void OutputFile::commit() {
  if (committed_) return;
  committed_ = true;
  switch (kind_) {
    case Kind::standard_output:
      std::cout.flush();
      if (!std::cout) throw std::runtime_error(option_ + ": could not finish writing to standard output");
      g_committed = true;
      return;
    case Kind::direct:
      if (const std::string why = close(); !why.empty())
        throw std::runtime_error(option_ + ": could not finish writing '" + path_ + "': " + why);
      g_committed = true;
      return;
    case Kind::growing:
    case Kind::replaced: break;
  }
  const std::string why = close();
  unkeep(tmp_.c_str());
  unregister_temporary(tmp_.c_str());
  std::error_code ec;
  if (!why.empty()) {
    if (kind_ == Kind::growing)
      throw std::runtime_error(option_ + ": could not finish writing '" + tmp_.string() + "': " + why + "; '" + path_ +
                               "' is left as it was, and the recording so far is in '" + tmp_.string() + "'");
    fs::remove(tmp_, ec);
    throw std::runtime_error(option_ + ": could not finish writing '" + path_ + "': " + why + "; it is left as it was");
  }
  fs::rename(tmp_, target_, ec);
  if (ec) {
    fs::remove(tmp_, ec);
    throw std::runtime_error(option_ + ": could not put '" + path_ + "' in place: " + ec.message());
  }
  g_committed = true;
}

void check_outputs(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs) {
  const NamedPath* on_stdout = nullptr;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const NamedPath& out = outputs[i];
    if (out.path.empty()) continue;
    if (out.path == "-") {
      if (on_stdout)
        throw BadInput(on_stdout->option + " and " + out.option +
                       " both write to standard output (-); give one of them a file name");
      on_stdout = &out;
      continue;
    }
    for (const NamedPath& in : inputs)
      if (!in.path.empty() && in.path != "-" && same_file(out.path, in.path))
        throw BadInput(out.option + " " + out.path + ": that is " + in.option + " (" + in.path +
                       "); writing it would overwrite it: give another file name");
    for (std::size_t j = 0; j < i; ++j)
      if (!outputs[j].path.empty() && outputs[j].path != "-" && same_file(out.path, outputs[j].path)) {
        // Two outputs into one device (/dev/null) are harmless; into one file, one would be lost.
        struct stat s{};
        if (::stat(out.path.c_str(), &s) == 0 && !S_ISREG(s.st_mode)) continue;
        throw BadInput(outputs[j].option + " and " + out.option + " both write '" + out.path +
                       "'; give each its own file");
      }
  }
}

bool any_output_committed() noexcept { return g_committed.load(); }

std::size_t keep_temporaries() noexcept {
  std::size_t kept = 0;
  for (Kept& k : g_kept) {
    const char* tmp = k.tmp.exchange(nullptr);
    const char* target = k.target.exchange(nullptr);
    if (tmp == nullptr || target == nullptr) continue;
    if (::rename(tmp, target) == 0) {
      ++kept;
      unregister_temporary(tmp);
    }
  }
  remove_temporaries();
  return kept;
}

void remove_temporaries() noexcept {
  for (auto& slot : g_temporaries)
    if (const char* p = slot.exchange(nullptr)) ::unlink(p);
}

}  // namespace turtlegas::apps
