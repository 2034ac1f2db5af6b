// Chapter 14's preconditioner: chapter 12's float V-cycle with its finest level run in pair
// lanes (fine_smoothing.hpp). The hierarchy, its float copy and every coarse level are
// chapter 12's; only the finest level's matrix gets another layout, filled from the double
// blocks after each factorization, and the V-cycle (chapter 10's v_cycle.hpp) runs on it
// through the level's own kernels, found by argument-dependent lookup.
#pragma once

#include <Eigen/Core>

#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/10_multigrid/multigrid.hpp"
#include "chapters/12_half_the_bytes/reduced_v_cycle.hpp"
#include "chapters/14_every_lane/fine_smoothing.hpp"

namespace fem::ch14 {

// The finest level's layout: a row's blocks in pairs, one pair per 256 bits of float (the
// faster on the AMD EPYC measured); RowPairFineLevel puts two rows' pairs in 512 bits.
using FineLanes = LaneFineLevel;

class LaneVCycle final : public ch09::Preconditioner {
 public:
  // Both must outlive this object; `reduced` reads `multigrid`'s levels.
  LaneVCycle(ch12::ReducedVCycle<float>& reduced, ch10::Multigrid& multigrid);

  // Chapter 12's prepare (chapter 10's factorize, its numbers into float), then the finest
  // level's double blocks into the lanes. By every thread.
  void prepare(const ch07::BlockSparseMatrix& A, const ch09::RowChunks& chunks) override;
  bool block_diagonal() const override { return false; }
  // s = M r: one float V-cycle from the lanes' finest level. By every thread.
  void apply(const ch09::RowChunks& chunks, const Eigen::VectorXd& r, Eigen::VectorXd& s) override;

  // A hierarchy of one level is its coarsest, solved by chapter 10's Cholesky factor: no lanes.
  bool lanes() const { return lanes_; }
  FineLanes& fine_level() { return fine_; }
  const FineLanes& fine_level() const { return fine_; }

 private:
  ch12::ReducedVCycle<float>& reduced_;
  ch10::Multigrid& multigrid_;
  bool lanes_;
  FineLanes fine_;
  Eigen::VectorXf r_, s_;  // the PCG's residual and its preconditioned residual in float
};

}  // namespace fem::ch14
