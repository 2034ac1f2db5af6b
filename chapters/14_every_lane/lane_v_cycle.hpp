// Chapter 14's preconditioner: chapter 12's float V-cycle with its finest level run in pair
// lanes (fine_smoothing.hpp). The hierarchy, its float copy and every coarse level are
// chapter 12's; only the finest level's matrix gets another layout, filled from the double
// blocks after each factorization, and the V-cycle (chapter 10's v_cycle.hpp) runs on it
// through the level's own kernels, found by argument-dependent lookup.
//
// Which layout depends on where the level will live. In cache, the kernel is held in the core
// and the padded pairs are the faster (a pair's column is one load, 48 bytes a block); from
// memory a kernel held by its bytes would favour the packed pairs, chapter 12's 36 bytes. The
// choice is made once, from the level's size against the last cache the machine reports,
// never from the thread count: the same bits on any number of threads. That rule is a
// measurement, not a law: the lesson's table (`fem_lessons every-lane`) times both layouts at
// one and two threads and says where the stepper runs the slower one.
#pragma once

#include <Eigen/Core>
#include <variant>

#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/10_multigrid/multigrid.hpp"
#include "chapters/12_half_the_bytes/reduced_v_cycle.hpp"
#include "chapters/14_every_lane/fine_smoothing.hpp"
#include "common/caches.hpp"

namespace fem::ch14 {

// The finest level's layouts: a row's blocks in pairs, one pair per 256 bits of float, padded
// where the level fits in the last cache, packed where it does not (the README's layout lines
// say, per mesh and thread count, which one measured faster); RowPairFineLevel puts two rows'
// pairs in 512 bits.
using InCacheLanes = LaneFineLevel;
using FromMemoryLanes = PackedFineLevel;

class LaneVCycle {
 public:
  // Both must outlive this object; `reduced` reads `multigrid`'s levels. The finest level is
  // padded when a smoothing step's data fit in `cache_bytes` (by default the last cache the
  // machine reports; 0 where it does not say: packed).
  LaneVCycle(ch12::ReducedVCycle<float>& reduced, ch10::Multigrid& multigrid,
             long long cache_bytes = last_cache_bytes());

  // Chapter 12's prepare (chapter 10's factorize, its numbers into float), then the finest
  // level's double blocks into the lanes. By every thread.
  void prepare(const ch07::BlockSparseMatrix& A);
  // s = M r: one float V-cycle from the lanes' finest level. By every thread.
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& s);

  // A hierarchy of one level is its coarsest, solved by chapter 10's Cholesky factor: no lanes.
  bool lanes() const { return lanes_; }
  bool in_cache() const { return std::holds_alternative<InCacheLanes>(fine_); }
  // f(the finest level in its layout).
  template <class F>
  decltype(auto) with_fine_level(F&& f) {
    return std::visit(f, fine_);
  }
  template <class F>
  decltype(auto) with_fine_level(F&& f) const {
    return std::visit(f, fine_);
  }

 private:
  ch12::ReducedVCycle<float>& reduced_;
  ch10::Multigrid& multigrid_;
  bool lanes_;
  std::variant<InCacheLanes, FromMemoryLanes> fine_;
  Eigen::VectorXf r_, s_;  // the PCG's residual and its preconditioned residual in float
};

}  // namespace fem::ch14
