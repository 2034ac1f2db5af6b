// Chapter 10: chapter 09's step, A dv = b filtered by PPCG and solved by the parallel PCG,
// with one change: the preconditioner. Block Jacobi becomes one V-cycle of smoothed-
// aggregation multigrid, set up once from the mesh (the constructor), its numbers refreshed
// every solve (prepare), applied once per PCG iteration (apply).
#include "chapters/10_multigrid/stepper.hpp"

namespace fem::ch10 {

namespace {

Eigen::VectorXd rest_positions(const Scene& scene) {
  return Eigen::Map<const Eigen::VectorXd>(scene.mesh.X.data(),
                                           static_cast<Eigen::Index>(scene.mesh.X.size()));
}

}  // namespace

void VCyclePreconditioner::prepare(const ch07::BlockSparseMatrix& A, const ch09::RowChunks&) {
  // Every thread of the solve's team: the multigrid shares out its own row blocks.
  multigrid_.prepare(A.blocks);
}

void VCyclePreconditioner::apply(const ch09::RowChunks&, const Eigen::VectorXd& r,
                                 Eigen::VectorXd& s) {
  // One V-cycle, on every thread of the team, ending with a barrier: the PCG then reads s on
  // any row. Filtered on both sides by the PCG, S M S is symmetric positive definite on the
  // free subspace, as PCG needs.
  multigrid_.apply(r, s);
}

MultigridStepper::MultigridStepper(const Scene& scene, const SolverSettings& settings,
                                   const MultigridSettings& multigrid,
                                   ch09::ElementParallelism element_parallelism)
    : ThreadsStepper(scene, settings, element_parallelism),
      // The hierarchy's set-up: aggregates, rigid-body modes at the rest positions, patterns.
      multigrid_(system_matrix().row_start, system_matrix().column, rest_positions(scene),
                 scene.constraints, multigrid),
      extrapolate_(multigrid.extrapolate_guess),
      previous_y_(Eigen::VectorXd::Zero(system_rhs().size())) {
  use_preconditioner(v_cycle_, "10_multigrid");
}

void MultigridStepper::solve() {
  // y_ holds the last solution. With two of them, the guess is the line through both,
  // 2 y_n - y_(n-1): the velocity change of a smooth motion changes smoothly. Element by
  // element on one thread: 3N multiply-adds, no sum, the same bits for any thread count.
  if (extrapolate_ && solves_ >= 2) {
    for (Eigen::Index k = 0; k < y_.size(); ++k) {
      const double last = y_[k];
      y_[k] = 2.0 * last - previous_y_[k];
      previous_y_[k] = last;
    }
  } else {
    previous_y_ = y_;
  }
  ++solves_;
  ThreadsStepper::solve();
}

}  // namespace fem::ch10
