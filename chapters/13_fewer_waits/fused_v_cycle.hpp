// Chapter 13's building block: chapter 10's V-cycle with fewer waits. Every loop of the cycle
// ends at a barrier, because the next loop reads rows that another thread wrote. But a loop
// whose work on a row reads only that row needs no barrier before it: it can run inside the
// loop before, on the rows that loop just wrote. The first smoothing step from zero is such
// work (d = beta D^-1 b, row by row), and so are the conversions in and out of float. So:
//  - the caller runs a level's first step in the loop that writes the level's b (fused_entry);
//  - the restriction runs the next level's first step on the coarse rows it just wrote;
//  - the restriction to the coarsest level and its dense solve run on one thread together;
//  - the last post-smoothing step runs the caller's `finish(first, last)` on its rows.
// Each thread still sums the same numbers in the same order on the same fixed row blocks as
// chapter 10's v_cycle: the result is that cycle's, to the bit, for any thread count.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "chapters/09_threads/parallel.hpp"
#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/10_multigrid/v_cycle.hpp"
#include "chapters/12_half_the_bytes/reduced_v_cycle.hpp"

namespace fem::ch13 {

// The first smoothing step from zero on rows [first, last) of `level`, into its x: what
// fused_cycle expects to have run on every row before it starts. (Chapter 10's settings check
// keeps at least one smoothing step: sweeps and Chebyshev degree >= 1.)
template <class Level, class Vector>
void fused_entry(Level& level, int first, int last, const Vector& b) {
  smooth(level, 0, first, last, b, static_cast<const Vector*>(nullptr), level.vectors.x, true);
}

template <class Level, class Coarse>
void correct_from_below(Level& level, std::vector<Coarse>& coarse, std::size_t next);

// The rest of one V-cycle on `level` (not the coarsest, shared by the team), after fused_entry
// ran on every row: b -> out (out may be the level's x); coarse[next] is the level below.
// finish(first, last) runs on the rows of out each thread has just written.
template <class Level, class Coarse, class Vector, class Finish>
void fused_cycle(Level& level, std::vector<Coarse>& coarse, std::size_t next, const Vector& b,
                 Vector& out, Finish&& finish) {
  const std::vector<int>& part = source_level(level).rows.part;
  const int steps = smoothing_steps(level);
  // Pre-smoothing: step 0 ran in fused_entry, into x; then the ping-pong of chapter 10.
  const Vector* current = &level.vectors.x;
  for (int k = 1; k < steps; ++k) {
    Vector& target = k % 2 == 0 ? level.vectors.x : level.vectors.y;
    ch09::for_parts(part, true, [&](int first, int last) {
      smooth(level, k, first, last, b, current, target, true);
    });
    current = &target;
  }
  ch09::for_parts(part, true,
                  [&](int first, int last) { residual(level, first, last, b, *current); });
  correct_from_below(level, coarse, next);
  ch09::for_parts(part, true, [&](int first, int last) {
    prolong_rows(level, coarse[next], first, last, *current);
  });
  current = &level.vectors.y;
  for (int k = 0; k < steps; ++k) {
    Vector& target = (steps - k) % 2 == 1 ? out : level.vectors.residual;
    ch09::for_parts(part, true, [&](int first, int last) {
      smooth(level, k, first, last, b, current, target, false);
      if (k == steps - 1) finish(first, last);
    });
    current = &target;
  }
}

// The coarse correction's way down: the residual restricted into the level below and that
// level's cycle, its x the correction. Three cases, by the level below:
//  - the coarsest: restriction and dense solve on one thread, one wait for both;
//  - a small level (serial): restriction and chapter 10's whole cycle on one thread;
//  - a shared level: its restriction runs its first step on the coarse rows just written.
template <class Level, class Coarse>
void correct_from_below(Level& level, std::vector<Coarse>& coarse, std::size_t next) {
  Coarse& below = coarse[next];
  const auto& rows = source_level(below).rows;
  const int coarse_rows = source_level(below).nodes();
  if (source_level(below).coarsest || rows.serial) {
    ch09::on_one_thread(true, [&] {
      restrict_rows(level, below, 0, coarse_rows);
      ch10::v_cycle(below, coarse, next + 1, below.vectors.b, below.vectors.x, false);
    });
    return;
  }
  ch09::for_parts(rows.part, true, [&](int first, int last) {
    restrict_rows(level, below, first, last);
    fused_entry(below, first, last, below.vectors.b);
  });
  fused_cycle(below, coarse, next + 1, below.vectors.b, below.vectors.x, [](int, int) {});
}

// A call f(first, last) passed by reference to a callable of any type, without std::function
// (which may allocate): the callable must outlive the call.
class RowsCall {
 public:
  template <class F>
  RowsCall(const F& f)  // NOLINT: converts from any callable, as std::function does
      : call_([](const void* f, int first, int last) { (*static_cast<const F*>(f))(first, last); }),
        callable_(&f) {}
  void operator()(int first, int last) const { call_(callable_, first, last); }

 private:
  void (*call_)(const void*, int, int);
  const void* callable_;
};

// The float V-cycle of the hierarchy as the PCG's preconditioner, run by fused_cycle: the same
// numbers (the float levels that `reduced` converts in prepare), the same result, four waits
// fewer per cycle on a three-level hierarchy (fused_v_cycle.cpp counts them).
class FusedVCycle {
 public:
  // `reduced` (its levels and its conversion) and the hierarchy it reads must outlive this.
  FusedVCycle(ch12::ReducedVCycle<float>& reduced, ch10::Multigrid& multigrid);
  void prepare(const ch07::BlockSparseMatrix& A);
  // s = M r: r into float inside the finest level's first step, s back to double inside its
  // last. By every thread of the PCG's team.
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& s);

  // The same cycle in two parts, for a solver that runs the first inside a loop of its own:
  // enter(first, last, r) on every row block of fine_part() as r's rows are written, then
  // complete(s, finish) by every thread after that loop's barrier, which calls
  // finish(first, last) on the rows of s as they are written. Only where fused() (a finest
  // level shared by the team, with a level below).
  bool fused() const;
  const std::vector<int>& fine_part() const { return reduced_.fine_level().source->rows.part; }
  void enter(int first, int last, const Eigen::VectorXd& r);
  void complete(Eigen::VectorXd& s, const RowsCall& finish);

 private:
  ch12::ReducedVCycle<float>& reduced_;
  ch10::Multigrid& multigrid_;  // its refresh rule counts the cycles
  Eigen::VectorXf r_, s_;       // the residual and the preconditioned residual in float
};

}  // namespace fem::ch13
