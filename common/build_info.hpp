// How this binary was built: recorded in every benchmark result.
#pragma once

#include <string>
#include <vector>

#include "common/json.hpp"

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

// What was measured: the commit (git describe --always --dirty --abbrev=7, "unknown" outside
// a git checkout) and the source files that differ from it. `--dirty` sees changes to tracked
// files only, so a student's new variant folder, untracked, would pass for the clean commit:
// uncommitted_sources() lists changed and untracked files under the measured sources
// (chapters/, common/, apps/, CMakeLists.txt; git status --porcelain --untracked-files=all).
struct SourceState {
  std::string commit;  // with "-dirty" appended when uncommitted is not empty
  std::vector<std::string>
      uncommitted;     // paths relative to the repository, e.g. "chapters/10_mine/stepper.cpp"
  bool known = false;  // false outside a git checkout (no git, a tarball)
};
SourceState source_state();
// Adds the fields "commit": ... and "uncommitted": [...] (null when unknown) to a JSON object.
void add_source_state(Json& out, const SourceState& s);

// Where the repository is (meshes are found relative to it when a path is relative).
std::string source_dir();

}  // namespace fem
