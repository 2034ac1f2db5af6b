#include "apps/roofline/lesson.hpp"

#include <sstream>

#include "apps/roofline/placement.hpp"
#include "apps/roofline/report.hpp"
#include "chapters/registry.hpp"
#include "common/build_info.hpp"
#include "common/mesh.hpp"

namespace fem::roofline {

namespace {

std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

// --chapters: "all" (the course's chapters, variants aside) or a list of ids and numbers.
std::vector<const ChapterInfo*> chapters_of(const std::string& list) {
  std::vector<const ChapterInfo*> out;
  if (list == "all") {
    for (const ChapterInfo& c : chapters())
      if (c.variant_of.empty()) out.push_back(&c);
    return out;
  }
  for (const std::string& id : split(list)) out.push_back(&find_chapter(id));
  return out;
}

// The run's scene with another mesh (same scene, material, time step, damping).
Scene on_mesh(const Scene& scene, const std::string& path) {
  Scene other = make_scene(scene.name, load_mesh(path), scene.material);
  other.dt = scene.dt;
  other.damping = scene.damping;
  return other;
}

std::vector<Roofs> machine_roofs(const LessonRun& run) {
  std::vector<CacheLevel> caches = cache_levels();
  if (caches.empty()) caches = fallback_levels();
  std::vector<int> counts = {1};
  if (run.args.get_int("threads-max") > 1) counts.push_back(run.args.get_int("threads-max"));
  std::vector<Roofs> roofs;
  for (const int t : counts)
    roofs.push_back(measure_roofs(caches, t, run.args.get_double("roof-seconds")));
  return roofs;
}

std::string sentence(const LessonRun& run, const std::vector<Roofs>& roofs) {
  std::ostringstream out;
  out << "\nRoofs: the best of repeated timings of each kernel, every thread on its own array "
      << "(read: a sum in " << 8 << " independent packet sums; peak: 12 independent chains of "
      << "Eigen packet multiply-adds, " << double_lanes() << " doubles or " << float_lanes()
      << " floats per packet), working sets from the caches in /sys/devices/system/cpu. "
      << roofs_check(roofs) << "Chapters: " << run.args.get_int("warmup") << " warm-up and "
      << run.steps << " measured steps, medians; cantilever scene. " << measured_on() << ".\n";
  return out.str();
}

std::string roofline_table(const LessonRun& run) {
  const int warmup = run.args.get_int("warmup");
  std::vector<Scene> others;  // loaded first: a bad path fails before any measurement
  for (const std::string& path : split(run.args.get("meshes")))
    others.push_back(on_mesh(run.scene, path));
  const std::vector<Roofs> roofs = machine_roofs(run);
  std::vector<ChapterRun> runs;
  for (const ChapterInfo* c : chapters_of(run.args.get("chapters")))
    for (ChapterRun& r : place_chapter(*c, run.scene, roofs, warmup, run.steps))
      runs.push_back(std::move(r));
  for (const Scene& scene : others)
    for (const ChapterInfo* c : chapters_of(run.args.get("other-chapters")))
      for (ChapterRun& r : place_chapter(*c, scene, roofs, warmup, run.steps))
        runs.push_back(std::move(r));
  if (run.data) *run.data = json_data(roofs, runs);
  return roofs_table(roofs) + "\n" + chapters_table(runs) + "\n" + phases_table(runs) +
         sentence(run, roofs);
}

void add_roofline_options(ArgParser& args) {
  args.option("chapters", "LIST", "chapters to place on the scene's mesh (ids or numbers)", "all");
  args.option("meshes", "LIST", "further meshes, comma-separated, for --other-chapters", "");
  args.option("other-chapters", "LIST", "chapters to place on each of --meshes",
              latest_chapter().id);
  args.option("threads-max", "N", "the second thread count of the roofs and chapters 09-12",
              std::to_string(hardware_threads()));
  args.option("warmup", "N", "unmeasured steps before the measured ones", "3");
  args.option("roof-seconds", "S", "time per roof kernel", "0.2");
}

}  // namespace

std::vector<Lesson> lessons() {
  Lesson roofline{"roofline",
                  "the machine's roofs (bandwidth per cache level, peak flops) and every "
                  "chapter's phases under them",
                  "meshes/plate_poster.msh",
                  add_roofline_options,
                  [](const LessonRun& run) { return roofline_table(run); },
                  true};
  roofline.readme = "docs/roofline.md";
  roofline.record_args = {"--steps", "20"};
  roofline.record_meshes_if_present = {"meshes/generated/beam_100k.msh"};
  return {roofline};
}

}  // namespace fem::roofline
