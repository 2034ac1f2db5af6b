#include "chapters/14_every_lane/lane_v_cycle.hpp"

#include "chapters/09_threads/parallel.hpp"
#include "chapters/10_multigrid/v_cycle.hpp"

namespace fem::ch14 {

LaneVCycle::LaneVCycle(ch12::ReducedVCycle<float>& reduced, ch10::Multigrid& multigrid)
    : reduced_(reduced),
      multigrid_(multigrid),
      lanes_(multigrid.levels() > 1),
      fine_(reduced.fine_level()),
      r_(Eigen::VectorXf::Zero(multigrid.fine_level().dofs())),
      s_(Eigen::VectorXf::Zero(multigrid.fine_level().dofs())) {}

void LaneVCycle::prepare(const ch07::BlockSparseMatrix& A, const ch09::RowChunks& chunks) {
  reduced_.prepare(A, chunks);
  if (!lanes_) return;
  // Each thread fills the row blocks it smooths (the same static share of the same parts).
  ch09::for_parts(source_level(fine_).rows.part, true,
                  [&](int first, int last) { fine_.fill(first, last); });
}

void LaneVCycle::apply(const ch09::RowChunks& chunks, const Eigen::VectorXd& r,
                       Eigen::VectorXd& s) {
  if (!lanes_) {
    reduced_.apply(chunks, r, s);
    return;
  }
  const std::vector<int>& part = source_level(fine_).rows.part;
  ch09::for_parts(part, true, [&](int first, int last) {
    r_.segment(3 * first, 3 * (last - first)) =
        r.segment(3 * first, 3 * (last - first)).cast<float>();
  });
  multigrid_.apply(fine_, reduced_.coarse_levels(), r_, s_);
  ch09::for_parts(part, true, [&](int first, int last) {
    s.segment(3 * first, 3 * (last - first)) =
        s_.segment(3 * first, 3 * (last - first)).cast<double>();
  });
}

}  // namespace fem::ch14
