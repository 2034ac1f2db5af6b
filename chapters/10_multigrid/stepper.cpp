// Chapter 10: chapter 09's step, A dv = b filtered by PPCG and solved by the parallel PCG,
// with two changes: the preconditioner, and the guess. Block Jacobi becomes one V-cycle of
// smoothed-aggregation multigrid, set up once from the mesh (analyze_pattern), its finest
// level refreshed every solve and its coarse levels every few (factorize), applied once per
// PCG iteration (apply); the guess is the polynomial through the last solutions.
#include "chapters/10_multigrid/stepper.hpp"

#include <algorithm>
#include <stdexcept>

namespace fem::ch10 {

namespace {

Eigen::VectorXd rest_positions(const Scene& scene) {
  return Eigen::Map<const Eigen::VectorXd>(scene.mesh.X.data(),
                                           static_cast<Eigen::Index>(scene.mesh.X.size()));
}

}  // namespace

void VCyclePreconditioner::prepare(const ch07::BlockSparseMatrix& A, const ch09::RowChunks&) {
  // Every thread of the solve's team: the multigrid shares out its own row blocks.
  multigrid_.factorize(A.blocks);
}

void VCyclePreconditioner::apply(const ch09::RowChunks&, const Eigen::VectorXd& r,
                                 Eigen::VectorXd& s) {
  // One V-cycle, on every thread of the team, ending with a barrier: the PCG then reads s on
  // any row. Filtered on both sides by the PCG, S M S is symmetric positive definite on the
  // free subspace, as PCG needs.
  multigrid_.apply(r, s);
}

void check(const MultigridStepperSettings& settings) {
  check(settings.multigrid);
  if (settings.extrapolation < 0 || settings.extrapolation > 2)
    throw std::invalid_argument("multigrid stepper: the guess's extrapolation order is 0, 1 or 2");
}

namespace {

// The hierarchy's settings, once all of the stepper's are checked: the first member built.
const MultigridSettings& checked(const MultigridStepperSettings& settings) {
  check(settings);
  return settings.multigrid;
}

}  // namespace

MultigridStepper::MultigridStepper(const Scene& scene, const SolverSettings& settings,
                                   const MultigridStepperSettings& multigrid,
                                   ch09::ElementParallelism element_parallelism)
    : ThreadsStepper(scene, settings, element_parallelism),
      multigrid_(checked(multigrid)),
      extrapolation_(multigrid.extrapolation) {
  // The hierarchy's set-up: aggregates, rigid-body modes at the rest positions, patterns.
  multigrid_.analyze_pattern(system_matrix().row_start, system_matrix().column,
                             rest_positions(scene), scene.constraints);
  for (auto& h : history_) h = Eigen::VectorXd::Zero(3 * scene.mesh.num_nodes());
  use_preconditioner(v_cycle_, "10_multigrid");
}

void MultigridStepper::solve() {
  // y_ holds the last solution y_n; history_ the two before it. The guess is the polynomial
  // through the last order + 1 solutions, evaluated one step ahead: y_n (order 0), 2 y_n -
  // y_(n-1) (1), 3 y_n - 3 y_(n-1) + y_(n-2) (2). The velocity change of a smooth motion
  // changes smoothly, so the guess starts closer. Element by element on one thread: a few
  // multiply-adds per unknown, no sum, the same bits for any thread count.
  static constexpr double kWeights[3][3] = {{1.0, 0.0, 0.0}, {2.0, -1.0, 0.0}, {3.0, -3.0, 1.0}};
  const int order = std::min(extrapolation_, solves_ - 1);  // only past solutions count
  for (Eigen::Index k = 0; k < y_.size(); ++k) {
    const double last = y_[k];
    if (order > 0) {
      double guess = kWeights[order][0] * last;
      for (int j = 1; j <= order; ++j) guess += kWeights[order][j] * history_[j - 1][k];
      y_[k] = guess;
    }
    history_[1][k] = history_[0][k];
    history_[0][k] = last;
  }
  ++solves_;
  ThreadsStepper::solve();
}

}  // namespace fem::ch10
