// Chapter 13's PCG with one wait per reduction: Chronopoulos and Gear's form of CG (1989).
// The PCG of chapter 09 meets its team four times per iteration outside the preconditioner: after
// q = A p (for p . q), after the update of y and r (for r . r), after s = M r (for r . s),
// and after p = s + beta p (q = A p reads p's neighbours). Here one loop computes w = A s and
// both dot products of the next step, gamma = r . s and delta = s . w, and the directions
// follow by recurrences, p = s + beta p and q = w + beta q (= A p, by linearity), in the
// update loop, which also runs the V-cycle's first step on the residual's new rows: two
// waits per iteration besides the cycle's own, and r . s is summed inside the cycle's last
// loop. Sums run over the finest level's fixed row blocks in their order, as chapter 09's.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/08_element_kernels/contract.hpp"
#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/13_fewer_waits/fused_v_cycle.hpp"
#include "common/stepper.hpp"

namespace fem::ch13 {

// Its kernels on the rows [first, last) of one row block, each returning the block's part of the
// sum it ends with: the solver's loops call them, and so does the roofline's kernels alone.
//   w = A s; s . w
double single_reduction_product(const ch08::ProductPart& A, const Eigen::VectorXd& s,
                                Eigen::VectorXd& w, int first, int last);
//   p = s + beta p, q = w + beta q, y += alpha p, r -= alpha q, r filtered; r . r
double single_reduction_update(double alpha, double beta, const Eigen::VectorXd& s,
                               const Eigen::VectorXd& w, Eigen::VectorXd& p, Eigen::VectorXd& q,
                               Eigen::VectorXd& y, Eigen::VectorXd& r,
                               const ch09::ChunkFilter& filter, int first, int last);

class SingleReductionPcg {
 public:
  // The rows of `part` are the fused cycle's finest row blocks (FusedVCycle::fine_part).
  SingleReductionPcg(const std::vector<int>& part, const std::vector<NodeConstraint>& constraints);
  // The filter's constraints from the next solve on (a grab, a release, a floor's contacts).
  void set_constraints(const std::vector<NodeConstraint>& constraints);
  // y holds the initial guess on entry and the solution on exit; the same stopping rule and
  // PPCG filter as chapter 09's PCG. M must be fused() (FusedVCycle).
  SolveStats solve(const ch07::BlockSparseMatrix& A, ch08::ProductPart& product, FusedVCycle& M,
                   const Eigen::VectorXd& b, const SolverSettings& settings, Eigen::VectorXd& y);

 private:
  struct Sums {  // this iteration's sums, the same on every thread
    double rr = 0.0, gamma = 0.0, delta = 0.0;
  };
  SolveStats iterate(const ch08::ProductPart& A, FusedVCycle& M, double rhs_norm2,
                     const SolverSettings& settings, Eigen::VectorXd& y);
  double start(const ch08::ProductPart& A, FusedVCycle& M, const Eigen::VectorXd& b,
               Eigen::VectorXd& y);  // r = S (b - A y), M's first step; ||b||^2
  Sums precondition_and_product(const ch08::ProductPart& A, FusedVCycle& M);     // s, w
  double update(FusedVCycle& M, double alpha, double beta, Eigen::VectorXd& y);  // ||r||^2
  ch09::ChunkFilter filter(int p) const {  // the PPCG projection on part p's nodes
    return {constraints_.data() + constraint_start_[p],
            constraints_.data() + constraint_start_[p + 1]};
  }
  double sum(const std::vector<double>& partial) const;

  std::vector<int> part_;
  std::vector<NodeConstraint> constraints_;  // sorted by node; part p's from constraint_start_[p]
  std::vector<int> constraint_start_;
  Eigen::VectorXd r_, s_, w_, p_, q_;
  // Per-part partial sums, one array per sum, so that none is written again while a slower
  // thread may still be adding it up.
  std::vector<double> partial_bb_, partial_rr_, partial_gamma_, partial_delta_;
};

}  // namespace fem::ch13
