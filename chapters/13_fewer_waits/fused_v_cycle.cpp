// Chapter 13: the float V-cycle with fewer waits (see fused_v_cycle.hpp). Per cycle on the
// plate's three levels, chapter 12's apply waits 21 times: the conversion in, 3 + 1 + 1 + 3 + 1
// on the finest level (pre-smoothing, residual, restriction, post-smoothing, prolongation),
// as many on the middle one, the coarsest solve, the conversion out. This one waits 17 times:
// the conversions, the middle level's first step and the coarsest restriction ride in loops
// that run anyway.
#include "chapters/13_fewer_waits/fused_v_cycle.hpp"

#include "chapters/12_half_the_bytes/reduced_kernels.hpp"

namespace fem::ch13 {

FusedVCycle::FusedVCycle(ch12::ReducedVCycle<float>& reduced, ch10::Multigrid& multigrid)
    : reduced_(reduced), multigrid_(multigrid) {
  const Eigen::Index dofs = reduced.fine_level().source->dofs();
  r_.setZero(dofs);
  s_.setZero(dofs);
}

void FusedVCycle::prepare(const ch07::BlockSparseMatrix& A) {
  reduced_.prepare(A);  // the hierarchy's numbers, then their float copies
}

bool FusedVCycle::fused() const {
  const ch10::Level<3>& source = *reduced_.fine_level().source;
  return !source.coarsest && !source.rows.serial;
}

void FusedVCycle::enter(int first, int last, const Eigen::VectorXd& r) {
  ch12::convert_rows(r, r_, first, last);
  fused_entry(reduced_.fine_level(), first, last, r_);
}

void FusedVCycle::complete(Eigen::VectorXd& s, const RowsCall& finish) {
  multigrid_.refresh_rule().count_cycle();  // the refresh rule counts V-cycles
  fused_cycle(reduced_.fine_level(), reduced_.coarse_levels(), 0, r_, s_, [&](int first, int last) {
    ch12::convert_rows(s_, s, first, last);
    finish(first, last);
  });
}

void FusedVCycle::apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) {
  if (!fused()) {  // one level, or a finest level below rows.serial_rows: nothing to fuse
    reduced_.apply(r, s);
    return;
  }
  ch09::for_parts(fine_part(), true, [&](int first, int last) { enter(first, last, r); });
  const auto nothing = [](int, int) {};
  complete(s, nothing);
}

}  // namespace fem::ch13
