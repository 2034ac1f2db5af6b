#include "common/build_info.hpp"

#include <Eigen/Core>
#include <fstream>
#include <thread>

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

}  // namespace fem
