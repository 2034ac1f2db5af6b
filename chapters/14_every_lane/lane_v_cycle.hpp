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
// them where they run: its first ten steps on each team size alternate the two (five each),
// each timed from its fill to its last V-cycle, so the PCG's product and updates between the
// cycles count (they run in the caches the layout leaves them), and it keeps the one of the
// shorter median. The state does not depend on the choice, only the time.
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
  // level's double blocks into the layout this team size runs (while it has not chosen: the
  // trial's next, and the last step's trial time recorded). By every thread, once a step.
  void prepare(const ch07::BlockSparseMatrix& A);
  // s = M r: one float V-cycle from the lanes' finest level. By every thread.
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& s);

  // A hierarchy of one level is its coarsest, solved by chapter 10's Cholesky factor: no lanes.
  bool lanes() const { return lanes_; }
  // The layout the last prepare filled, which apply runs.
  Layout layout() const { return current_; }
  // The layout measured faster on a team of `threads`, once its trial is over.
  std::optional<Layout> measured(int threads) const;
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
  static constexpr int kTeams = 64;  // team sizes remembered (a larger one shares the last)
  static constexpr int kTrials = 5;  // steps timed in each layout
  // One team size's trial: the seconds of each step's fill and solve, padded's then packed's.
  struct Trial {
    int steps = 0;
    std::array<double, 2 * kTrials> seconds{};
    Layout next() const;
    void record(Layout layout, double time);
    Layout faster();  // reorders `seconds`
  };
  void end_trial_step();  // the last step's time into its team's trial, once it has one

  ch12::ReducedVCycle<float>& reduced_;
  ch10::Multigrid& multigrid_;
  bool lanes_;
  std::optional<Layout> forced_;
  std::array<signed char, kTeams + 1> measured_;  // per team size: -1, or the faster Layout
  std::array<Trial, kTeams + 1> trials_;
  Layout current_;
  int trial_team_ = 0;    // the team size the last prepare's step is a trial of, or 0
  double started_ = 0.0;  // that step's fill began, by one thread's clock
  double ended_ = 0.0;    // its last V-cycle so far ended
  PaddedLanes padded_;
  PackedLanes packed_;
  Eigen::VectorXf r_, s_;  // the PCG's residual and its preconditioned residual in float
};

}  // namespace fem::ch14
