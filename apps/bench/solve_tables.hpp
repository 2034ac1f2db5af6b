// The poster's solve table: stock Eigen solvers and the chapters' own, each on the same
// sequence of filtered systems, timed apart from the rest of a step.
#pragma once

#include <string>
#include <vector>

#include "apps/bench/schedule.hpp"
#include "common/scene.hpp"
#include "common/stepper.hpp"

namespace fem::bench {

struct SolverResult {
  std::string name;
  double median_ms = 0.0, setup_ms = 0.0, solve_ms = 0.0, iterations = 0.0,
         allocations_per_solve = 0.0;
};

// On the filtered systems of a run of chapter 06 on the scene, on one thread. Each solver
// solves every system from the same inputs; "guess" solvers start from the previous system's
// solution (ours). The pattern never changes, so the factorizing solvers analyse it once
// (analyzePattern, not timed) and factorize every step: setup_ms is compute() or factorize(),
// solve_ms the solve.
std::vector<SolverResult> run_solvers(const Scene& scene, const SolverSettings& settings,
                                      const Schedule& schedule);

// The threaded rows, on chapter 09's systems (the same filtered systems as chapter 06's,
// assembled in another order): stock Eigen's threaded CG, ConjugateGradient<RowMajor,
// Lower|Upper> with Eigen::setNbThreads(n) (its SpMV is an OpenMP loop over rows,
// sparse_time_dense_product_impl in Eigen/src/SparseCore/SparseDenseProduct.h; a column-major
// matrix with Lower|Upper reaches the same loop through its transpose, TransposeInput in
// ConjugateGradient.h), against chapter 09's solver with n OpenMP threads. Both start from
// the previous system's solution.
std::vector<SolverResult> run_threaded_solvers(const Scene& scene, const SolverSettings& settings,
                                               const std::vector<int>& thread_counts,
                                               const Schedule& schedule);

}  // namespace fem::bench
