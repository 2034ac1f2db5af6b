#include "apps/roofline/lesson.hpp"

#include <algorithm>
#include <iostream>
#include <sstream>

#include "apps/roofline/kernels_alone.hpp"
#include "apps/roofline/placement.hpp"
#include "apps/roofline/report.hpp"
#include "chapters/registry.hpp"
#include "common/build_info.hpp"

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

std::vector<Roofs> machine_roofs(const LessonRun& run) {
  const std::vector<CacheLevel> caches = cache_levels();
  std::vector<int> counts = {1};
  if (run.args.get_int("threads-max") > 1) counts.push_back(run.args.get_int("threads-max"));
  std::vector<Roofs> roofs;
  for (const int t : counts)
    roofs.push_back(measure_roofs(caches, t, run.args.get_double("roof-seconds"),
                                  !run.args.has_flag("no-likwid")));
  return roofs;
}

// Why the roofs have no likwid-bench check: not asked for, or likwid-bench's own note (not
// installed, as on arm64 and macOS, or no report), so that a run without it says so.
std::string unchecked_why(const std::vector<Roofs>& roofs) {
  const std::string note = roofs.empty() || roofs.front().levels.empty()
                               ? std::string()
                               : roofs.front().levels.front().likwid_read.note;
  return note.empty() ? "likwid-bench's check not asked for (--no-likwid)" : note;
}

// How a roof was sampled: beside its likwid-bench check where that ran (measure_roofs).
std::string sampling(const std::vector<Roofs>& roofs, double seconds) {
  const bool checked = !roofs.empty() && !roofs.front().levels.empty() &&
                       roofs.front().levels.front().likwid_read.rate > 0.0;
  std::ostringstream out;
  if (checked)
    out << "one timing of each roof and one likwid-bench run back to back, "
        << fixed(std::max(seconds / kRoofRounds, kLikwidRunSeconds), 1) << " s each, in "
        << kRoofRounds << " rounds, the best of each (likwid-bench one process a thread, "
        << "each pinned to its CPU, started at once, their rates summed)";
  else
    out << "the best of repeated timings in " << kRoofRounds
        << " rounds, unchecked: " << unchecked_why(roofs);
  return out.str();
}

std::string sentence(const LessonRun& run, const std::vector<Roofs>& roofs) {
  std::ostringstream out;
  out << "\nRoofs: the best of repeated timings of each kernel, every thread on its own array "
      << "(read: packet loads, " << read_packets()
      << " a stride, each kept by an empty asm statement and not summed, as likwid-bench's; "
      << "write: packet stores; update: each packet loaded and stored back, a written byte of a "
      << "line the pass read first priced at 2 / update - 1 / read; zeroing: compose's own loop "
      << "of 3x3 blocks zeroed; "
      << "peak: " << fma_chains() << " independent chains of Eigen packet multiply-adds, "
      << double_lanes() << " doubles or " << float_lanes()
      << " floats per packet); a team timed from the barrier that starts it to the one after its "
      << "last thread ends, each thread pinned to its own CPU; "
      << sampling(roofs, run.args.get_double("roof-seconds")) << "; working sets from the caches "
      << "in /sys/devices/system/cpu, a shared cache holding no more than its roofs were "
      << "measured on. " << roofs_check(roofs) << "Chapters: " << run.args.get_int("warmup")
      << " warm-up and " << run.steps << " measured steps, medians; cantilever scene. "
      << measured_on() << ".\n";
  return out.str();
}

std::string roofline_table(const LessonRun& run) {
  const int warmup = run.args.get_int("warmup");
  // Loaded first: a bad path or chapter fails before any measurement.
  const std::vector<Scene> others = more_meshes(run);
  const std::vector<const ChapterInfo*> alone_chapters =
      chapters_of(run.args.get("alone-chapters"));
  const std::vector<Roofs> roofs = machine_roofs(run);
  std::vector<PlacedRun> runs;
  for (const ChapterInfo* c : chapters_of(run.args.get("chapters")))
    for (PlacedRun& r : place_chapter(*c, run.scene, roofs, warmup, run.steps))
      runs.push_back(std::move(r));
  for (const Scene& scene : others)
    for (const ChapterInfo* c : chapters_of(run.args.get("other-chapters")))
      for (PlacedRun& r : place_chapter(*c, scene, roofs, warmup, run.steps))
        runs.push_back(std::move(r));
  const std::vector<AloneRun> alone = kernels_alone(alone_chapters, run.scene, roofs, runs);
  // Printed here, not in the table: the page shows it in its own section (roofline-kernels-alone).
  std::cout << kernels_alone_table(alone) << "\n";
  const std::string provisional = run.args.get("provisional");
  if (run.data) *run.data = with_kernels_alone(json_data(roofs, runs, provisional), alone);
  const std::string banner =
      provisional.empty()
          ? ""
          : "**Provisional data, not a measurement to read: " + provisional + ".**\n\n";
  return banner + roofs_table(roofs) + "\n" + roofs_checked(roofs) + "\n" + chapters_table(runs) +
         "\n" + phases_table(runs) + broken_bounds(runs) + sentence(run, roofs);
}

void add_roofline_options(ArgParser& args) {
  args.option("chapters", "LIST", "chapters to place on the scene's mesh (ids or numbers)", "all");
  args.option("meshes", "LIST", "further meshes, comma-separated, for --other-chapters", "");
  args.option("other-chapters", "LIST", "chapters to place on each of --meshes",
              latest_chapter().id);
  args.option("threads-max", "N",
              "the second thread count of the roofs and of the chapters whose stepper uses "
              "threads (09 to " +
                  latest_chapter().id.substr(0, 2) + ")",
              std::to_string(hardware_threads()));
  args.option("warmup", "N", "unmeasured steps before the measured ones (fem_bench's default)",
              "10");
  args.option("roof-seconds", "S", "time per roof kernel", "0.2");
  args.option("alone-chapters", "LIST",
              "chapters whose solve's kernels run alone on the scene's mesh (ids, numbers or all; "
              "empty: none)",
              "09,12,13,14");
  args.flag("no-likwid", "skip likwid-bench's check of the roofs");
  args.option("provisional", "REASON",
              "mark the data provisional (the docs check then warns instead of refusing)", "");
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
  // fem_bench's window (10 warm-up and 100 measured steps from rest), so that the book's
  // roofline and its bench table time the same steps; roofs timed long enough to be quiet.
  roofline.record_args = {"--steps", "100", "--warmup", "10", "--roof-seconds", "0.5"};
  roofline.record_meshes_if_present = {"meshes/generated/beam_100k.msh"};
  return {roofline};
}

}  // namespace fem::roofline
