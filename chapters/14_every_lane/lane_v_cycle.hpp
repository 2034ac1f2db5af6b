// Chapter 14's preconditioner: chapter 12's float V-cycle with its finest level run in pair
// lanes (fine_smoothing.hpp). The hierarchy, its float copy and every coarse level are
// chapter 12's; only the finest level's matrix gets another layout, filled from the double
// blocks after each factorization, and the V-cycle (chapter 10's v_cycle.hpp) runs on it
// through the level's own kernels, found by argument-dependent lookup.
//
// Which layout is faster is a measurement, not a rule. Padded pairs (a pair's column one load,
// 48 bytes a block) take fewer instructions; packed pairs (36 bytes a block, chapter 12's)
// read fewer bytes. Which wins depends on the caches, the memory and the thread count: the
// book's recordings found the padded faster on one machine and the packed on another for the
// same level, and the two orders swapped between one thread and two. The layouts compute the
// same bits (fine_smoothing_rows.hpp spells out the one multiply-add), so the stepper times
// them where they run: the first prepare on each team size fills each layout five times in
// turn and runs three V-cycles from it, timed from the fill to the last cycle's end, and keeps
// the one of the shorter median. The trial runs on that step's own matrix and spends no step
// of the simulation: the first step on a team is longer, and every later one is the same step
// it would be in the other layout. The state does not depend on the choice, only the time.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>

#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/10_multigrid/multigrid.hpp"
#include "chapters/12_half_the_bytes/reduced_v_cycle.hpp"
#include "chapters/14_every_lane/fine_smoothing.hpp"

namespace fem::ch14 {

// The finest level's two layouts the stepper chooses from: a row's blocks in pairs, one pair
// per 256 bits of float, padded or packed; RowPairFineLevel (row_pairs.hpp) puts two rows'
// pairs in 512 bits.
using PaddedLanes = LaneFineLevel;
using PackedLanes = PackedFineLevel;
enum class Layout : signed char { padded, packed };

class LaneVCycle {
 public:
  // Both must outlive this object; `reduced` reads `multigrid`'s levels. `forced`: run that
  // layout on every team (the tests); without, each team size runs the one it measured faster.
  LaneVCycle(ch12::ReducedVCycle<float>& reduced, ch10::Multigrid& multigrid,
             std::optional<Layout> forced = std::nullopt);

  // Chapter 12's prepare (chapter 10's factorize, its numbers into float), then the finest
  // level's double blocks into the layout this team size runs (on a team size not seen
  // before, after the trial that chooses it). By every thread, once a step.
  void prepare(const ch07::BlockSparseMatrix& A);
  // s = M r: one float V-cycle from the lanes' finest level. By every thread.
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& s);

  // A hierarchy of one level is its coarsest, solved by chapter 10's Cholesky factor: no lanes.
  bool lanes() const { return lanes_; }
  // The layout the last prepare filled, which apply runs.
  Layout layout() const { return current_; }
  // The layout measured faster on a team of `threads`, once its trial is over.
  std::optional<Layout> measured(int threads) const;
  // That trial's times in seconds, padded's then packed's (zeros before it ran).
  static constexpr int kTrials = 5;                 // fills timed in each layout
  using Seconds = std::array<double, 2 * kTrials>;  // padded's, then packed's
  const Seconds& trial_seconds(int threads) const;
  // From the next prepare on, run `layout` on every team (std::nullopt: the measured one), as
  // `forced` does; the lesson's whole steps in each layout. Between steps, not in a V-cycle.
  void force(std::optional<Layout> layout) { forced_ = layout; }
  // f(the finest level in the layout it runs).
  template <class F>
  decltype(auto) with_fine_level(F&& f) {
    return current_ == Layout::padded ? f(padded_) : f(packed_);
  }
  template <class F>
  decltype(auto) with_fine_level(F&& f) const {
    return current_ == Layout::padded ? f(padded_) : f(packed_);
  }

 private:
  static constexpr int kTeams = 64;       // team sizes remembered (a larger one shares the last)
  static constexpr int kCycles = 3;       // V-cycles timed after each fill
  static Layout turn(int k);              // the trial's k-th layout
  static Layout faster(Seconds seconds);  // the one of the shorter median
  // By every thread: the trial on a team of `team`, and the layout it chose filled.
  void trial(int team);
  void fill(Layout layout);  // by every thread, into current_

  ch12::ReducedVCycle<float>& reduced_;
  ch10::Multigrid& multigrid_;
  bool lanes_;
  std::optional<Layout> forced_;
  std::array<signed char, kTeams + 1> measured_;  // per team size: -1, or the faster Layout
  std::array<Seconds, kTeams + 1> trials_{};
  Layout current_;
  double started_ = 0.0;  // the trial's turn began, by one thread's clock (shared by the team)
  PaddedLanes padded_;
  PackedLanes packed_;
  Eigen::VectorXf r_, s_;  // the PCG's residual and its preconditioned residual in float
};

}  // namespace fem::ch14
