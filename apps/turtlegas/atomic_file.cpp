// SPDX-License-Identifier: MIT
#include "atomic_file.hpp"

#include <unistd.h>

#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

#include "cli_common.hpp"

namespace turtlegas::apps {

namespace fs = std::filesystem;

AtomicFile::AtomicFile(fs::path target, std::string_view option) : target_(std::move(target)) {
  const fs::path dir = target_.parent_path().empty() ? fs::path(".") : target_.parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw BadInput(std::string(option) + ": directory '" + dir.string() + "' does not exist; create it first");
  if (fs::is_directory(target_, ec))
    throw BadInput(std::string(option) + ": '" + target_.string() + "' is a directory; give a file name");
  tmp_ = dir / ("." + target_.filename().string() + ".tmp-" + std::to_string(::getpid()));
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_) throw BadInput(std::string(option) + ": cannot write in '" + dir.string() + "'; check its permissions");
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  out_.close();
  std::error_code ec;
  fs::remove(tmp_, ec);
}

void AtomicFile::commit() {
  out_.close();
  if (out_.fail()) throw std::runtime_error("could not finish writing '" + target_.string() + "' (disk full?)");
  fs::rename(tmp_, target_);
  committed_ = true;
}

}  // namespace turtlegas::apps
