// The chapter table of fem_bench: every chapter stepped on the same scene, in turns of a few
// steps each, and its per-phase times and allocations summarized.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "apps/bench/schedule.hpp"
#include "chapters/registry.hpp"
#include "common/statistics.hpp"

namespace fem::bench {

struct ChapterResult {
  std::string chapter;  // "09_threads@2": a chapter that uses threads, with its thread count
  std::string title;
  std::string variant_of;                             // a student's variant: its original
  std::string source_hash;                            // the chapter folder's sources, at build time
  std::array<Spread, StepProfile::kPhaseCount> ms{};  // per phase (StepProfile::phases()), ms
  double allocations_per_step = 0.0;                  // median over the measured steps
  std::array<long long, StepProfile::kPhaseCount> phase_allocations{};  // the last step's
  long long allocations_max = 0;
  double cg_iterations = 0.0;      // median
  double relative_residual = 0.0;  // last step
  int not_converged_steps = 0;
  int threads = 1;  // the thread count of the run: 1 for the single-threaded chapters
  // The threads the measured steps ran on, by the stepper's own record (chapter 09's adaptive
  // team takes one thread while that is faster); 0 where the chapter does not say.
  int threads_fewest = 0, threads_most = 0;
};

// Runs the chapters interleaved, Schedule::turn steps of each in turn: when the machine's
// speed drifts (a shared virtual machine, a CPU changing its clock), every chapter sees the
// same drift, so their ratios hold even when the absolute times move. A chapter that uses threads
// (09 on) runs once per thread count. Throws when a chapter's simulation diverges.
std::vector<ChapterResult> run_chapters(const std::vector<const ChapterInfo*>& chapters,
                                        const Scene& scene, const SolverSettings& solver,
                                        const std::vector<int>& thread_counts,
                                        const Schedule& schedule);

}  // namespace fem::bench
