// SPDX-License-Identifier: MIT
// `turtlegas sweep`: the journal that makes a sweep resumable.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "checkpoint.hpp"
#include "cli_common.hpp"
#include "sweep/sweep.hpp"

namespace turtlegas::apps::sweep {

namespace fs = std::filesystem;

std::string fingerprint(const Spec& spec) {
  char b[32];
  std::snprintf(b, sizeof b, "%016llx",
                static_cast<unsigned long long>(fnv1a64(spec.text.dump() + "\n" + spec.world.dump())));
  return b;
}

Journal::Journal(const std::string& out, const Spec& spec, Results& results) : path_(out + ".partial") {
  const std::string fp = fingerprint(spec);
  std::vector<std::string> good;
  if (fs::exists(path_)) {
    std::ifstream in(path_);
    std::string line;
    bool first = true;
    while (std::getline(in, line)) {
      const json j = json::parse(line, nullptr, false);
      if (first) {
        first = false;
        if (j.is_discarded() || j.value("fingerprint", "") != fp)
          throw BadInput(path_ + ": a partial sweep of another spec or world (delete it, or choose another --out)");
        continue;
      }
      if (j.is_discarded() || !j.contains("run") || !j["run"].is_number_unsigned() || in.eof()) continue;
      const std::size_t k = j["run"].get<std::size_t>();
      if (k < spec.runs && !results.count(k)) {
        results[k] = line;
        good.push_back(line);
      }
    }
  }
  // Rewritten whole (a cut line gone), then appended to.
  {
    std::ofstream rewrite(path_ + ".tmp", std::ios::trunc);
    rewrite << json{{"fingerprint", fp}, {"spec", spec.file}}.dump() << '\n';
    for (const std::string& l : good) rewrite << l << '\n';
    if (!rewrite) throw BadInput(path_ + ": cannot write the sweep's journal here");
  }
  fs::rename(path_ + ".tmp", path_);
  out_.open(path_, std::ios::app);
  if (!out_) throw BadInput(path_ + ": cannot write the sweep's journal here");
}

void Journal::record(const std::string& line) {
  out_ << line << '\n';
  out_.flush();
}

void Journal::remove() {
  out_.close();
  fs::remove(path_);
}

}  // namespace turtlegas::apps::sweep
