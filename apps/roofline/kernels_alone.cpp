#include "apps/roofline/kernels_alone.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <memory>

#include "chapters/course.hpp"
#include "chapters/registry.hpp"
#include "common/lesson.hpp"
#include "common/threads.hpp"

namespace fem::roofline {

namespace {

constexpr int kTimings = 15;         // timings per kernel; the best is kept
constexpr double kMinTiming = 2e-3;  // seconds: calls per timing doubled up to this
constexpr int kSteps = 3;            // steps before the kernels run: A, the hierarchy, its vectors

}  // namespace

std::vector<KernelAlone> solve_kernels(const ChapterInfo& chapter, Stepper& stepper,
                                       const Scene& scene, double iterations) {
  // The kernels are the stepper's parts' own (CourseChapter::work.kernels), on the parts' data:
  // the caller's own stepper, not one it steps on.
  std::vector<KernelAlone> kernels;
  const ChapterWork& work = course_of(chapter).work;
  if (!work.kernels) return kernels;
  for (PartKernel& k : work.kernels(stepper, scene, iterations)) {
    KernelAlone alone;
    alone.name = std::move(k.name);
    alone.part = std::move(k.part);
    alone.work = std::move(k.work);
    alone.calls = k.calls;
    alone.run = std::move(k.run);
    kernels.push_back(std::move(alone));
  }
  return kernels;
}

double best_call_seconds(int threads, const std::function<void()>& kernel) {
  using Clock = std::chrono::steady_clock;
  const ThreadCountScope team(threads);
  double best = std::numeric_limits<double>::infinity();
  int calls = 1;
  for (int timed = 0; timed < kTimings;) {
    const Clock::time_point start = Clock::now();
    // Every thread of the team calls the kernel, which shares its loop out (orphaned `omp
    // for`), as inside a step's parallel region.
#pragma omp parallel num_threads(threads)
    for (int i = 0; i < calls; ++i) kernel();
    const double t = std::chrono::duration<double>(Clock::now() - start).count();
    if (t < kMinTiming && calls < (1 << 24)) {
      calls *= 2;  // the first timings also bring the data into the cache
      continue;
    }
    best = std::min(best, t / calls);
    ++timed;
  }
  return best;
}

namespace {

const PlacedRun* placed(const std::vector<PlacedRun>& runs, const std::string& chapter,
                        const std::string& mesh, int threads) {
  for (const PlacedRun& r : runs)
    if (r.chapter == chapter && r.mesh == mesh && r.threads == threads) return &r;
  return nullptr;
}

// The placed solve, and the bound of the parts the kernels make up.
void set_solve(AloneRun& out, const Roofs& roofs, const PlacedRun& run) {
  for (const PhasePoint& p : run.phases) {
    if (p.work.phase != "solve") continue;
    out.solve_s = p.measured_s;
    out.waiting_s = p.waiting_s;
    out.solve_bound_s = p.bound_s;
    for (const PhaseWork& part : p.work.parts)
      if (std::any_of(out.kernels.begin(), out.kernels.end(),
                      [&](const KernelAlone& k) { return k.part == part.phase; }))
        out.parts_bound_s += bound_seconds(roofs, part);
  }
}

AloneRun measure_alone(const ChapterInfo& chapter, const Scene& scene, const Roofs& roofs,
                       const PlacedRun& run) {
  AloneRun out;
  out.chapter = chapter.id;
  out.mesh = run.mesh;
  out.threads = roofs.threads;
  const ThreadCountScope team(roofs.threads);
  std::unique_ptr<Stepper> stepper = chapter.make(scene, SolverSettings{});
  State state = rest_state(scene);
  for (int k = 0; k < kSteps; ++k) stepper->step(state);
  out.kernels = solve_kernels(chapter, *stepper, scene, run.iterations);
  for (KernelAlone& k : out.kernels) {
    k.bound_s = bound_seconds(roofs, k.work);
    k.seconds = best_call_seconds(roofs.threads, k.run);
    out.alone_s += k.calls * k.seconds;
  }
  set_solve(out, roofs, run);
  return out;
}

}  // namespace

std::vector<AloneRun> kernels_alone(const std::vector<const ChapterInfo*>& chapters,
                                    const Scene& scene, const std::vector<Roofs>& roofs,
                                    const std::vector<PlacedRun>& runs) {
  std::vector<AloneRun> out;
  for (const ChapterInfo* c : chapters) {
    const ChapterInfo& chapter = *c;
    for (const Roofs& r : roofs) {
      const PlacedRun* run = placed(runs, chapter.id, mesh_name(scene), r.threads);
      if (!run || run->phases.empty()) continue;  // not placed at this count, or not counted
      progress("roofline: " + chapter.id + "'s kernels alone at " + std::to_string(r.threads) +
               " thread(s)");
      out.push_back(measure_alone(chapter, scene, r, *run));
    }
  }
  return out;
}

}  // namespace fem::roofline
