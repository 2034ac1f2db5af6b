// How this binary was built: recorded in every benchmark result.
#pragma once

#include <string>

namespace fem {

struct BuildInfo {
  std::string compiler;    // e.g. "GNU 12.2.0"
  std::string flags;       // the C++ flags of this build type, e.g. "-O3 -DNDEBUG -Wall ..."
  std::string build_type;  // Release, Debug
  std::string eigen;       // e.g. "3.4.0"
};
BuildInfo build_info();

// The CPU model from /proc/cpuinfo ("unknown" elsewhere) and the hardware threads.
std::string cpu_model();
unsigned hardware_threads();

// Where the repository is (meshes are found relative to it when a path is relative).
std::string source_dir();

}  // namespace fem
