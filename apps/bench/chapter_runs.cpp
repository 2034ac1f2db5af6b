#include "apps/bench/chapter_runs.hpp"

#include <chrono>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "common/alloc_counter.hpp"
#include "common/cli.hpp"
#include "common/threads.hpp"

namespace fem::bench {

namespace {

std::array<PhaseCost, 6> phases(const StepProfile& p) {
  return {p.forces, p.dfdx, p.compose, p.constraints, p.solve, p.step};
}

// One chapter's stepper, state and samples while the benchmark runs.
struct ChapterRun {
  int threads = 1;
  std::unique_ptr<Stepper> stepper;
  State state;
  std::array<std::vector<double>, 6> ms;
  std::vector<double> allocations, iterations;
  ChapterResult result;
};

// A run per chapter, and per thread count for a chapter that uses threads ("09_threads@2").
std::vector<ChapterRun> make_runs(const std::vector<const ChapterInfo*>& chapters,
                                  const Scene& scene, const SolverSettings& solver,
                                  const std::vector<int>& thread_counts) {
  std::vector<ChapterRun> runs;
  for (const ChapterInfo* c : chapters) {
    std::unique_ptr<Stepper> first = c->make(scene, solver);
    const bool threaded = first->uses_threads();
    for (const int threads : threaded ? thread_counts : std::vector<int>{1}) {
      ChapterRun run;
      run.threads = threads;
      run.stepper = first ? std::move(first) : c->make(scene, solver);
      run.state = rest_state(scene);
      run.result.chapter = threaded ? c->id + "@" + std::to_string(threads) : c->id;
      run.result.title = c->title;
      run.result.variant_of = c->variant_of;
      run.result.source_hash = c->source_hash;
      run.result.threads = threads;
      runs.push_back(std::move(run));
    }
  }
  return runs;
}

// Step k of one run; its profile becomes samples when the step is a measured one.
void step(ChapterRun& run, int k, bool measured) {
  set_threads(run.threads);  // the next parallel region's team; no cost between steps
  alloc::Scope counter;
  run.stepper->step(run.state);
  const long long allocs = counter.allocations();
  if (const char* why = divergence(run.state, run.stepper->profile()))
    throw std::runtime_error(run.result.chapter + ": the simulation diverged at step " +
                             std::to_string(k + 1) + " (" + why + ")");
  if (!measured) return;
  ChapterResult& r = run.result;
  const StepProfile& p = run.stepper->profile();
  const auto s = phases(p);
  for (std::size_t i = 0; i < s.size(); ++i) {
    run.ms[i].push_back(1e3 * s[i].seconds);
    r.phase_allocations[i] = s[i].allocations;  // deterministic: the last step's
  }
  run.allocations.push_back(static_cast<double>(allocs));
  r.allocations_max = std::max(r.allocations_max, allocs);
  run.iterations.push_back(p.cg_iterations);
  r.relative_residual = p.relative_residual;
  r.not_converged_steps += p.converged ? 0 : 1;
}

ChapterResult summary(const ChapterRun& run) {
  ChapterResult r = run.result;
  for (std::size_t i = 0; i < run.ms.size(); ++i) r.ms[i] = spread(run.ms[i]);
  r.allocations_per_step = median(run.allocations);
  r.cg_iterations = median(run.iterations);
  if (r.not_converged_steps > 0)
    std::cout << "  warning: " << r.chapter << ": " << r.not_converged_steps
              << " steps stopped at the CG iteration cap\n";
  return r;
}

}  // namespace

std::vector<ChapterResult> run_chapters(const std::vector<const ChapterInfo*>& chapters,
                                        const Scene& scene, const SolverSettings& solver,
                                        const std::vector<int>& thread_counts,
                                        const Schedule& schedule) {
  std::vector<ChapterRun> runs = make_runs(chapters, scene, solver, thread_counts);
  for (int k = 0; k < schedule.total(); ++k) {
    const auto start = std::chrono::steady_clock::now();
    for (ChapterRun& run : runs) step(run, k, schedule.measured(k));
    // The first round allocates the steppers' buffers: the estimate is taken from the second.
    if (k == 1)
      announce_long_run(
          "fem_bench",
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
          schedule.total());
    if (schedule.reports(k))
      std::cout << "  step " << k + 1 << "/" << schedule.total() << " of every chapter\n"
                << std::flush;
  }
  std::vector<ChapterResult> results;
  for (const ChapterRun& run : runs) results.push_back(summary(run));
  return results;
}

}  // namespace fem::bench
