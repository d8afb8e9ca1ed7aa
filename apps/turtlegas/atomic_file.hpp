// SPDX-License-Identifier: MIT
// Output files that appear whole or not at all.
#pragma once

#include <filesystem>
#include <fstream>
#include <string_view>

namespace turtlegas::apps {

/// An output file written under a temporary name in the same directory and renamed over the
/// target only by commit(), so a failed or interrupted run never leaves a file that looks whole.
/// Opening it checks the path (BadInput, naming `option`, for a missing directory, a directory
/// given as the file, or one that cannot be written in), so a bad path costs nothing.
class AtomicFile {
 public:
  AtomicFile(std::filesystem::path target, std::string_view option);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  /// Removes the temporary file unless committed.
  ~AtomicFile();

  std::ofstream& stream() { return out_; }

  /// Closes the file and renames it over the target; throws std::runtime_error when the writes
  /// failed (a full disk, say).
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path tmp_;
  std::ofstream out_;
  bool committed_ = false;
};

}  // namespace turtlegas::apps
