// The remainder of a solve, named: its dominant kernels run alone, called again and again on
// the same data (so that the data sit in the cache level their working set fits, as the
// bound assumes), timed (the best of repeated timings) and set beside their own bounds from
// the same roofs. A kernel alone slower than its bound costs in the core (instructions,
// indexing, the latency of its small blocks); a solve slower than the sum of its kernels
// alone loses the rest between them (short loops, the coarse levels, data evicted between
// kernels, waiting). The kernels are the chapters' own: chapter 07's block product on chapter
// 09's row chunks, chapter 09's block Jacobi, chapter 12's float smoothing step (chapter 10's
// polynomial step on its levels); the PCG's vector updates are Eigen's, on vectors of the
// fine level's size.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "apps/roofline/placement.hpp"
#include "apps/roofline/roofs.hpp"
#include "chapters/work.hpp"

namespace fem::roofline {

struct KernelAlone {
  std::string name;
  std::string part;           // the solve's part (PhaseWork::parts) it is, or with others makes up
  PhaseWork work;             // one call
  double calls = 0.0;         // per step
  double seconds = 0.0;       // one call, the best of the timings
  double bound_s = 0.0;       // one call under the roofs
  std::function<void()> run;  // one call, by every thread of a team (or by one thread)
};

// The dominant kernels of `stepper`'s solve (chapter 09's ThreadsStepper and the steppers
// derived from it; chapter 12's and 13's float levels add the fine level's smoothing step),
// each with its work per call and its calls per step at `iterations` CG iterations per
// solve. Empty for a stepper of an earlier chapter. The stepper must have taken a step; the
// kernels write its work vectors.
// The solve's kernels of `stepper`, which `chapter` made and which ran a few steps, at
// `iterations` PCG iterations a step: its parts' own (CourseChapter::work.kernels).
std::vector<KernelAlone> solve_kernels(const ChapterInfo& chapter, Stepper& stepper,
                                       const Scene& scene, double iterations);

// Seconds of one call of `kernel` on `threads` threads: the best of repeated timings, each of
// enough calls in one parallel region to trust the clock. Each call ends at its loop's barrier,
// as in the solve.
double best_call_seconds(int threads, const std::function<void()>& kernel);

// One chapter's solve at one thread count beside its kernels alone.
struct AloneRun {
  std::string chapter, mesh;
  int threads = 1;
  std::vector<KernelAlone> kernels;
  double solve_s = 0.0;           // the best solve of the steps timed in turn with the kernels
  double solve_iterations = 0.0;  // its PCG iterations, at which the kernels' calls are counted
  int solve_rounds = 0;           // the steps timed in turn with the kernels
  double solve_bound_s = 0.0;     // its bound at those iterations
  double parts_bound_s = 0.0;     // the bound of the parts the kernels make up
  double alone_s = 0.0;           // the kernels alone: calls x seconds, summed
  double waiting_s = 0.0;         // the solve's waiting (in its bound)
};

// Each of `chapters` placed in `runs` on `scene`, at each thread count of `roofs`: a fresh
// stepper, a few steps in, then its solve and its kernels alone timed in turn
// (the best of each), under those roofs and against the placement's bound.
std::vector<AloneRun> kernels_alone(const std::vector<const ChapterInfo*>& chapters,
                                    const Scene& scene, const std::vector<Roofs>& roofs,
                                    const std::vector<PlacedRun>& runs);

// The table (Markdown) and a sentence on how to read it; empty when there is nothing.
std::string kernels_alone_table(const std::vector<AloneRun>& runs);
// `data` (the lesson's JSON object) with a "kernels_alone" section added.
std::string with_kernels_alone(const std::string& data, const std::vector<AloneRun>& runs);

}  // namespace fem::roofline
