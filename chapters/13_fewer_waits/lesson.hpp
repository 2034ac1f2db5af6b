// The measurement behind chapter 13's exercise on iterations: `fem_lessons iterations`, this
// chapter's stepper with other multigrid settings (the smoother's degree and interval, damped
// Jacobi, the coarsest level's size, the modes, the prolongator) on one scene: its PCG
// iterations per step and the solve's bytes per iteration and per step, as the roofline counts
// them (chapter 12's work.cpp), against the chapter's own settings. Counts only: the same on
// any machine and thread count.
#pragma once

#include <vector>

#include "chapters/10_multigrid/stepper.hpp"
#include "common/lesson.hpp"

namespace fem::ch13 {

// What one setting costs: this chapter's stepper run `warmup` unmeasured steps and `steps`
// measured ones from rest (fem_bench's schedule), its PCG iterations per measured step, and the
// roofline's count of the solve's bytes (chapter 12's count_work) per iteration and per step.
struct IterationCost {
  int levels = 0;
  double median_iterations = 0.0, mean_iterations = 0.0;
  double bytes_per_iteration = 0.0;  // one PCG iteration: the SpMV, the vectors, one V-cycle
  double bytes_per_step = 0.0;       // the solve at the mean iterations, prepare included
  long long refreshes = 0;           // of the coarse levels, over all the steps
};
// Throws std::runtime_error if a step diverges or a solve does not converge.
IterationCost iteration_cost(const Scene& scene, const SolverSettings& solver,
                             const ch10::MultigridStepperSettings& settings, int warmup, int steps);

std::vector<Lesson> lessons();

}  // namespace fem::ch13
