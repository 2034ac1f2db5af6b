#include "common/lesson.hpp"

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "common/build_info.hpp"
#include "common/machine_record.hpp"
#include "common/mesh.hpp"

namespace fem {

void progress(const std::string& what) {
  std::cerr << "  fem_lessons: " << what << "\n" << std::flush;
}

std::string fixed(double v, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << v;
  return out.str();
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

std::vector<Scene> more_meshes(const LessonRun& run) {
  std::vector<Scene> scenes;
  std::stringstream list(run.args.get("meshes"));
  for (std::string path; std::getline(list, path, ',');) {
    if (path.empty()) continue;
    scenes.push_back(make_scene(run.scene.name, load_mesh(path), run.scene.material));
    scenes.back().dt = run.scene.dt;
    scenes.back().damping = run.scene.damping;
  }
  return scenes;
}

std::string on_every_mesh(const LessonRun& run,
                          const std::function<std::string(const LessonRun&)>& table,
                          const std::string& separator) {
  const std::vector<Scene> scenes = more_meshes(run);
  std::string tables = table(run);
  for (const Scene& scene : scenes)
    tables += separator + table({run.args, scene, run.steps, run.chapter});
  return tables;
}

void step_progress(const std::string& name, int k, int total, int every) {
  if (k % every == 0)
    progress(name + ": step " + std::to_string(k + 1) + " of " + std::to_string(total));
}

}  // namespace fem
