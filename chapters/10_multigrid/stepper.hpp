// Chapter 10: a solve that grows far more slowly with the mesh. Chapter 09's threaded step (the
// fused element pass, the block SpMV over fixed row chunks, sums in chunk order) with one V-cycle
// of smoothed-aggregation multigrid (multigrid.hpp) as the PCG's preconditioner in place of
// block Jacobi: the preconditioner Tamstorf, Jones & McCormick 2015 pair with their PPCG.
// The V-cycle runs on every thread of the PCG's team over fixed row blocks, with sums in a
// fixed order, so the result is still the same to the last bit for any thread count; the
// guess is extrapolated from the last solutions.
#pragma once

#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/09_threads/stepper.hpp"
#include "chapters/10_multigrid/multigrid.hpp"

namespace fem::ch10 {

// The stepper's settings: the hierarchy's, and the PCG's guess.
struct MultigridStepperSettings {
  MultigridSettings multigrid;
  // The guess: the polynomial through the last extrapolation + 1 solutions one step ahead
  // (0: the last solution, chapter 09's warm start; 1: 2 y_n - y_(n-1); 2: 3 y_n - 3 y_(n-1)
  // + y_(n-2)).
  int extrapolation = 2;
};
// check(settings.multigrid) and the extrapolation's order; throws std::invalid_argument.
void check(const MultigridStepperSettings& settings);

// One V-cycle of the hierarchy as the preconditioner of chapter 09's PCG: prepare() gives
// the hierarchy this solve's matrix (factorize), apply() runs one cycle from a zero guess.
class VCyclePreconditioner final : public ch09::Preconditioner {
 public:
  explicit VCyclePreconditioner(Multigrid& multigrid) : multigrid_(multigrid) {}
  void prepare(const ch07::BlockSparseMatrix& A, const ch09::RowChunks& chunks) override;
  bool block_diagonal() const override { return false; }
  void apply(const ch09::RowChunks& chunks, const Eigen::VectorXd& r, Eigen::VectorXd& s) override;

 private:
  Multigrid& multigrid_;
};

// Not final: a derived stepper may run this step on other data (a renumbered mesh).
class MultigridStepper : public ch09::ThreadsStepper {
 public:
  MultigridStepper(
      const Scene& scene, const SolverSettings& settings,
      const MultigridStepperSettings& multigrid = {},
      ch09::ElementParallelism element_parallelism = ch09::ElementParallelism::colouring);

  const Multigrid& multigrid() const { return multigrid_; }
  Multigrid& multigrid() { return multigrid_; }

 private:
  // Chapter 09's solve from a guess extrapolated from the last solutions.
  void solve() override;

  Multigrid multigrid_;  // its pattern analysed from the system matrix's
  VCyclePreconditioner v_cycle_{multigrid_};
  int extrapolation_;           // the guess's order: 0, 1 or 2
  Eigen::VectorXd history_[2];  // the solutions of the two steps before the last
  int solves_ = 0;
};

}  // namespace fem::ch10
