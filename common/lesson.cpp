#include "common/lesson.hpp"

#include <algorithm>
#include <filesystem>
#include <iostream>

#include "common/build_info.hpp"
#include "common/machine_record.hpp"

namespace fem {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void progress(const std::string& what) {
  std::cerr << "  fem_lessons: " << what << "\n" << std::flush;
}

std::string code(const std::string& s) {
  std::string out = "`";
  for (const char c : s) out += (c == '|') ? '/' : c;  // keep Markdown table cells intact
  return out + "`";
}

std::string mesh_name(const Scene& scene) {
  return std::filesystem::path(scene.mesh.file).filename().string();
}

std::string measured_on() {
  const BuildInfo info = build_info();
  return cpu_model() + ", " + machine_summary(machine_record()) + ", " + info.compiler + ", `" +
         info.flags + "`";
}

}  // namespace fem
