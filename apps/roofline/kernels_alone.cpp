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

namespace {

// One timing: `calls` calls of `kernel` by every thread of a team of `threads`, in seconds.
double timing(int threads, const std::function<void()>& kernel, int calls) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  // Every thread of the team calls the kernel, which shares its loop out (orphaned `omp
  // for`), as inside a step's parallel region.
#pragma omp parallel num_threads(threads)
  for (int i = 0; i < calls; ++i) kernel();
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The calls one timing needs to last kMinTiming (the first timings also bring the data into
// the cache).
int calls_per_timing(int threads, const std::function<void()>& kernel) {
  int calls = 1;
  while (timing(threads, kernel, calls) < kMinTiming && calls < (1 << 24)) calls *= 2;
  return calls;
}

}  // namespace

double best_call_seconds(int threads, const std::function<void()>& kernel) {
  const ThreadCountScope team(threads);
  const int calls = calls_per_timing(threads, kernel);
  double best = std::numeric_limits<double>::infinity();
  for (int timed = 0; timed < kTimings; ++timed)
    best = std::min(best, timing(threads, kernel, calls) / calls);
  return best;
}

namespace {

const PlacedRun* placed(const std::vector<PlacedRun>& runs, const std::string& chapter,
                        const std::string& mesh, int threads) {
  for (const PlacedRun& r : runs)
    if (r.chapter == chapter && r.mesh == mesh && r.threads == threads) return &r;
  return nullptr;
}

// The solve's bound at the iterations of the one timed (its work counted by the chapter's hook,
// its waiting the placement's), and the bound of the parts the kernels make up.
void set_solve(AloneRun& out, const ChapterInfo& chapter, const Stepper& stepper,
               const Scene& scene, const Roofs& roofs, const PlacedRun& run) {
  for (const PhasePoint& p : run.phases)
    if (p.work.phase == "solve") out.waiting_s = p.waiting_s;
  const WorkCounts counts{out.solve_iterations, run.executed};
  for (const PhaseWork& w : course_of(chapter).work.count(stepper, scene, counts)) {
    if (w.phase != "solve") continue;
    out.solve_bound_s = bound_seconds(roofs, w) + out.waiting_s;
    for (const PhaseWork& part : w.parts)
      if (std::any_of(out.kernels.begin(), out.kernels.end(),
                      [&](const KernelAlone& k) { return k.part == part.phase; }))
        out.parts_bound_s += bound_seconds(roofs, part);
  }
}

// The kernels' calls at `iterations` PCG iterations, set on `kernels` (the same list in the
// same order as solve_kernels gave).
void set_calls(std::vector<KernelAlone>& kernels, const ChapterInfo& chapter, Stepper& stepper,
               const Scene& scene, double iterations) {
  const std::vector<KernelAlone> at = solve_kernels(chapter, stepper, scene, iterations);
  for (std::size_t i = 0; i < kernels.size(); ++i) kernels[i].calls = at[i].calls;
}

// The solve and its kernels alone timed in turn, kTimings rounds of one step (its solve timed)
// and one timing of each kernel, so that a drift of the machine's speed weighs on both: the
// best of each is kept, and the kernels' calls are those of the best solve's iterations. (A
// solve timed in other minutes than its kernels, as the placement's median, drifted by tens of
// percent against them on a shared machine: "between the kernels" changed sign between books.)
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
  std::vector<int> calls;
  for (KernelAlone& k : out.kernels) {
    k.bound_s = bound_seconds(roofs, k.work);
    k.seconds = std::numeric_limits<double>::infinity();
    calls.push_back(calls_per_timing(roofs.threads, k.run));
  }
  out.solve_s = std::numeric_limits<double>::infinity();
  for (int round = 0; round < kTimings; ++round) {
    stepper->step(state);
    const StepProfile& p = stepper->profile();
    if (p.solve.seconds < out.solve_s) {
      out.solve_s = p.solve.seconds;
      out.solve_iterations = p.cg_iterations;
    }
    for (std::size_t i = 0; i < out.kernels.size(); ++i)
      out.kernels[i].seconds = std::min(
          out.kernels[i].seconds, timing(roofs.threads, out.kernels[i].run, calls[i]) / calls[i]);
    ++out.solve_rounds;
  }
  set_calls(out.kernels, chapter, *stepper, scene, out.solve_iterations);
  for (const KernelAlone& k : out.kernels) out.alone_s += k.calls * k.seconds;
  set_solve(out, chapter, *stepper, scene, roofs, run);
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
