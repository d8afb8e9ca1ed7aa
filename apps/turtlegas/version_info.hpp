// SPDX-License-Identifier: MIT
// What `turtlegas --version` prints: written at build time by cmake/write_version.cmake.
#pragma once

#include <string>

namespace turtlegas::apps {

extern const char* const version_string;      ///< the project's version, "0.1.0"
extern const char* const version_commit;      ///< the git commit built ("-dirty" with local changes), or "unknown"
extern const char* const version_build_type;  ///< CMAKE_BUILD_TYPE
extern const char* const version_compiler;    ///< "GNU 12.2.0"
extern const char* const version_mpi;         ///< the MPI library sweep uses, or "no"

/// "turtlegas 0.1.0\ncommit ...\nbuild Release, GNU 12.2.0\nMPI ...\n"
inline std::string version_text() {
  return std::string("turtlegas ") + version_string + "\ncommit " + version_commit + "\nbuild " + version_build_type +
         ", " + version_compiler + "\nmpi " + version_mpi + "\n";
}

}  // namespace turtlegas::apps
