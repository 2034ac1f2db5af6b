// What a lesson's measurement is: the code behind a table of a chapter's README. It lives in
// its chapter (chapters/NN_name/lesson.cpp, declared in lesson.hpp), the registry lists it
// with the chapter, and fem_lessons runs it by name, for the chapter or a student's variant
// of it (a variant's copy of lesson.cpp measures the variant's code).
#pragma once

#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "common/cli.hpp"
#include "common/scene.hpp"
#include "common/statistics.hpp"

namespace fem {

// What a lesson's table is computed from.
struct LessonRun {
  const ArgParser& args;  // the lesson's own options, parsed
  const Scene& scene;
  int steps;            // measured steps or solves (--steps)
  std::string chapter;  // the chapter (or variant) whose code is measured
  // Where a lesson may leave its numbers as one JSON value, recorded beside its table as
  // "data" (the roofline's plot reads them); null when nobody records them.
  std::string* data = nullptr;
};

struct Lesson {
  std::string name;          // e.g. "rotations": `fem_lessons rotations`
  std::string summary;       // one line for --help
  std::string default_mesh;  // e.g. "meshes/plate_poster.msh"
  // The lesson's options beyond the scene, --steps, --threads, --readme and --chapter (may be
  // empty).
  std::function<void(ArgParser&)> add_options;
  // The lesson's Markdown table (and the sentence under it that says how it was measured).
  std::function<std::string(const LessonRun&)> table;
  // False: the table is measured on one thread (OpenMP's and Eigen's counts at 1), as the
  // chapters before 09 run; true: at the thread counts the lesson chooses (--threads).
  bool uses_threads = false;
  // False: the table holds counts only (iterations, bytes), which a busy machine does not
  // change, so fem_lessons adds no busy-machine warning under it.
  bool timed = true;
  // Where the table goes (between its markers): empty for its chapter's README; a lesson of
  // the whole course (the roofline) names its page.
  std::string readme = "";
  // How `fem_lessons record-all` records the table (docs/data/lessons/NAME.json): its options
  // beyond the defaults, and meshes added to its --meshes where they exist (the large ones
  // `./tutorial.sh meshes --large` generates, which a fresh clone lacks).
  std::vector<std::string> record_args = {};
  std::vector<std::string> record_meshes_if_present = {};
};

// ---- what the measurements share ----------------------------------------------------------

// Median wall-clock milliseconds (std::chrono::steady_clock) of f, run `repeat` times but
// stopped once `budget_s` seconds are spent (after one run at least), so that a lesson on a
// large mesh finishes in bounded time.
template <class F>
double time_ms(int repeat, F&& f, double budget_s = 10.0);

// Progress of a long lesson, on stderr so that stdout stays the Markdown table.
void progress(const std::string& what);

// v with `digits` digits after the point, for a table cell.
std::string fixed(double v, int digits);

// `s` as Markdown code, with '|' replaced so that a table cell stays intact.
std::string code(const std::string& s);

// "plate_poster.msh": the mesh's file name, for the sentence under a table.
std::string mesh_name(const Scene& scene);

// "AMD EPYC ..., GNU 12.2.0, `-O3 ...`": where and how a table was measured.
std::string measured_on();

// The run's scene (its name, material, time step and damping) on each mesh of the lesson's
// comma-separated --meshes option: a table for each. All are loaded before any is measured,
// so that a bad path fails at once.
std::vector<Scene> more_meshes(const LessonRun& run);

// table(run), then table on each of more_meshes(run), each after `separator`.
std::string on_every_mesh(const LessonRun& run,
                          const std::function<std::string(const LessonRun&)>& table,
                          const std::string& separator = "\n");

// "name: step k + 1 of total" every `every` steps of a lesson's loop (progress()).
void step_progress(const std::string& name, int k, int total, int every);

// ---- definitions of the templates -----------------------------------------------------

template <class F>
double time_ms(int repeat, F&& f, double budget_s) {
  std::vector<double> ms;
  double spent = 0.0;
  for (int k = 0; k < repeat && (k == 0 || spent < budget_s); ++k) {
    const auto start = std::chrono::steady_clock::now();
    f();
    ms.push_back(1e3 *
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    spent += 1e-3 * ms.back();
  }
  return median(ms);
}

}  // namespace fem
