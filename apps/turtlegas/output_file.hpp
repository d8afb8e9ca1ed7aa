// SPDX-License-Identifier: MIT
// The files a command writes: standard output, devices and pipes written directly, regular files
// replaced whole or not at all, and never one of the command's own inputs.
#pragma once

#include <filesystem>
#include <fstream>
#include <ostream>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

namespace turtlegas::apps {

namespace detail {
/// A file buffer that keeps why its first failed write failed (errno at that write), which an
/// ofstream forgets.
class CheckedFileBuf : public std::filebuf {
 public:
  int error = 0;  ///< errno of the first failed write (0: none, or one errno did not name)

 protected:
  int_type overflow(int_type c) override;
  std::streamsize xsputn(const char* s, std::streamsize n) override;
  int sync() override;
};
}  // namespace detail

/// An output file named on the command line (`option` names it in messages):
/// - "-" is standard output;
/// - a path to something that is not a regular file (a terminal, a FIFO such as bash's
///   `>(jq ...)`, /dev/null, or a symlink to one of those) is opened and written directly;
/// - a regular file, or a name that does not exist yet, is written under a temporary name in
///   the same directory and renamed over it by commit(), so that a failed or interrupted run never
///   leaves a file that looks whole. A symlink is followed: the file it points to is replaced
///   (keeping its permissions), the link stays.
/// Opening checks the path (BadInput for a missing directory, a directory given as the file, or
/// one that cannot be written in), so a bad path costs nothing. The temporary file is removed by
/// the destructor unless committed, and by a fatal signal or exit() (remove_temporaries()).
///
/// A growing output (a recording, docs/recording.md) is written under the name `<path>.partial`
/// beside the target, flushed as it goes, and renamed over the target by commit(). A run killed on
/// the way (SIGKILL, a crash, a full disk) leaves the target as it was and the `.partial` file
/// readable up to where it got (such a file marks its own end, and its reader says how much of an
/// unfinished one it recovered); it is never removed by the program.
class OutputFile {
 public:
  enum class Write { replace, growing };
  OutputFile(const std::string& path, std::string_view option, Write how = Write::replace);
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  ~OutputFile();

  std::ostream& stream();
  /// Hands what has been written so far on to the target (a reader of a pipe or of standard
  /// output sees it at once; a replaced file's temporary has it on disk).
  void flush();
  /// Marks the file as worth keeping as far as it was flushed when a busy loop ends the process
  /// (keep_temporaries()): an event log, flushed whole lines at a time.
  void keep_on_busy_loop();
  /// Finishes the file: closes it and, for a replaced or growing file, renames it over the
  /// target. Throws std::runtime_error when a write failed, saying why (strerror: "No space left on
  /// device") and leaving the target as it was.
  void commit();

  const std::string& path() const { return path_; }
  /// Why a write failed ("No space left on device"), or "" when none has.
  std::string failure() const;
  bool to_stdout() const { return kind_ == Kind::standard_output; }

 private:
  enum class Kind { standard_output, direct, replaced, growing };
  std::string path_;
  std::string option_;
  Kind kind_ = Kind::replaced;
  std::filesystem::path target_;  // the file replaced (a symlink's target) or written directly
  std::filesystem::path tmp_;
  detail::CheckedFileBuf buf_;
  std::ostream out_{&buf_};
  bool committed_ = false;
  /// Closes the file: "" or why it is not whole.
  std::string close();
};

/// A file named on the command line, and the option that named it ("--events"; the world file's
/// is "the world file").
struct NamedPath {
  std::string path;
  std::string option;
};

/// Refuses (BadInput, exit code 2) an output that is one of the inputs (the same file, by any
/// name or link: `--svg w.json` would overwrite the world), two outputs that are the same file,
/// and two outputs on standard output. Empty paths are ignored.
void check_outputs(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs);

/// Whether an output has been put in place (committed) by this process: async-signal-safe, for
/// the crash report.
bool any_output_committed() noexcept;

/// Renames the temporary of every file marked by keep_on_busy_loop() over its target and removes
/// the others; the number kept. Async-signal-safe (rename and unlink only), for the busy-loop exit
/// (turtle::set_busy_loop_last_words).
std::size_t keep_temporaries() noexcept;

/// Removes every OutputFile's temporary file now: async-signal-safe (unlink only), for a fatal
/// signal's handler and for exit() (crash_report.hpp).
void remove_temporaries() noexcept;

}  // namespace turtlegas::apps
