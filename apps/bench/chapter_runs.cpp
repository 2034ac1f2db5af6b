#include "apps/bench/chapter_runs.hpp"

#include <algorithm>
#include <chrono>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "common/alloc_counter.hpp"
#include "common/cli.hpp"
#include "common/threads.hpp"

namespace fem::bench {

namespace {

// One chapter's stepper, state and samples while the benchmark runs.
struct RunningChapter {
  int threads = 1;
  std::unique_ptr<Stepper> stepper;
  State state;
  std::array<std::vector<double>, StepProfile::kPhaseCount> ms;
  std::vector<double> allocations, iterations;
  ChapterResult result;
};

// A run per chapter, and per thread count for a chapter that uses threads ("09_threads@2").
std::vector<RunningChapter> make_runs(const std::vector<const ChapterInfo*>& chapters,
                                      const Scene& scene, const SolverSettings& solver,
                                      const std::vector<int>& thread_counts) {
  std::vector<RunningChapter> runs;
  for (const ChapterInfo* c : chapters) {
    std::unique_ptr<Stepper> first = c->make(scene, solver);
    const bool threaded = first->uses_threads();
    for (const int threads : threaded ? thread_counts : std::vector<int>{1}) {
      RunningChapter run;
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
void step(RunningChapter& run, int k, bool measured) {
  set_threads(run.threads);  // the next parallel region's team; no cost between steps
  alloc::Scope counter;
  run.stepper->step(run.state);
  const long long allocs = counter.allocations();
  stop_if_interrupted();
  if (const char* why = divergence(run.state, run.stepper->profile()))
    throw std::runtime_error(run.result.chapter + ": the simulation diverged at step " +
                             std::to_string(k + 1) + " (" + why + ")");
  if (!measured) return;
  ChapterResult& r = run.result;
  const StepProfile& p = run.stepper->profile();
  std::size_t i = 0;
  p.for_each_phase([&](const char*, const PhaseCost& cost) {
    run.ms[i].push_back(1e3 * cost.seconds);
    r.phase_allocations[i++] = cost.allocations;  // deterministic: the last step's
  });
  run.allocations.push_back(static_cast<double>(allocs));
  r.allocations_max = std::max(r.allocations_max, allocs);
  run.iterations.push_back(p.cg_iterations);
  // The stepper's own record of the threads its step ran on (0: it does not say).
  if (const int team = run.stepper->uses_threads() ? run.stepper->threads_used() : 0) {
    r.threads_fewest = r.threads_fewest == 0 ? team : std::min(r.threads_fewest, team);
    r.threads_most = std::max(r.threads_most, team);
  }
  r.relative_residual = p.relative_residual;
  r.not_converged_steps += p.converged ? 0 : 1;
}

ChapterResult summary(const RunningChapter& run) {
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
  std::vector<RunningChapter> runs = make_runs(chapters, scene, solver, thread_counts);
  using Clock = std::chrono::steady_clock;
  for (int first = 0; first < schedule.total(); first += Schedule::turn) {
    const int last = std::min(schedule.total(), first + Schedule::turn);
    double seconds = 0.0;  // the turn's steps but each chapter's first, which allocates
    for (RunningChapter& run : runs)
      for (int k = first; k < last; ++k) {
        const auto start = Clock::now();
        step(run, k, schedule.measured(k));
        if (k > 0) seconds += std::chrono::duration<double>(Clock::now() - start).count();
      }
    if (first == 0 && last > 1)
      announce_long_run("fem_bench", seconds / (last - 1), schedule.total());
    for (int k = first; k < last; ++k)
      if (schedule.reports(k))
        std::cout << "  step " << k + 1 << "/" << schedule.total() << " of every chapter\n"
                  << std::flush;
  }
  std::vector<ChapterResult> results;
  for (const RunningChapter& run : runs) results.push_back(summary(run));
  return results;
}

}  // namespace fem::bench
