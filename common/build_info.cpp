#include "common/build_info.hpp"

#include <Eigen/Core>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>

#include "common/json.hpp"

namespace fem {

BuildInfo build_info() {
  return {FEM_COMPILER, FEM_BUILD_FLAGS, FEM_BUILD_TYPE,
          std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) + "." +
              std::to_string(EIGEN_MINOR_VERSION)};
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  }
  return "unknown";
}

unsigned hardware_threads() { return std::thread::hardware_concurrency(); }

std::string source_dir() { return FEM_SOURCE_DIR; }

namespace {

// The output of a shell command, and whether it ran and exited with 0.
bool run(const std::string& command, std::string& out) {
  out.clear();
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return false;
  char buf[256];
  while (std::fgets(buf, sizeof buf, pipe)) out += buf;
  return pclose(pipe) == 0;
}

}  // namespace

SourceState source_state() {
  SourceState s;
  const std::string git = "git -C '" + source_dir() + "' ";
  std::string out;
  if (!run(git + "describe --always --dirty --abbrev=7 2>/dev/null", out) || out.empty()) {
    s.commit = "unknown";
    return s;
  }
  s.commit = out.substr(0, out.find_first_of("\n "));
  if (!run(git + "status --porcelain --untracked-files=all -- chapters common apps CMakeLists.txt "
                 "CMakePresets.json 2>/dev/null",
           out)) {
    return s;  // the commit is known, the changes are not: known stays false
  }
  s.known = true;
  std::istringstream lines(out);
  std::string line;
  while (std::getline(lines, line))
    if (line.size() > 3) s.uncommitted.push_back(line.substr(3));  // "XY path"
  const std::string dirty = "-dirty";
  const bool marked = s.commit.size() >= dirty.size() &&
                      s.commit.compare(s.commit.size() - dirty.size(), dirty.size(), dirty) == 0;
  if (!s.uncommitted.empty() && !marked) s.commit += dirty;
  return s;
}

void add_source_state(Json& out, const SourceState& s) {
  out["commit"] = s.commit;
  out["uncommitted"] = s.known ? Json(s.uncommitted) : Json();
}

}  // namespace fem
