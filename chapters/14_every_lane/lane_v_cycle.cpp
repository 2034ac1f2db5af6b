#include "chapters/14_every_lane/lane_v_cycle.hpp"

#include "chapters/09_threads/parallel.hpp"
#include "chapters/10_multigrid/v_cycle.hpp"

namespace fem::ch14 {

namespace {

std::variant<InCacheLanes, FromMemoryLanes> fine_lanes(ch12::ReducedLevel<float, 3>& level,
                                                       long long cache_bytes) {
  InCacheLanes padded(level);
  if (padded.smoothing_work().working_set <= double(cache_bytes)) return padded;
  return FromMemoryLanes(level);
}

}  // namespace

LaneVCycle::LaneVCycle(ch12::ReducedVCycle<float>& reduced, ch10::Multigrid& multigrid,
                       long long cache_bytes)
    : reduced_(reduced),
      multigrid_(multigrid),
      lanes_(multigrid.levels() > 1),
      fine_(fine_lanes(reduced.fine_level(), cache_bytes)),
      r_(Eigen::VectorXf::Zero(multigrid.fine_level().dofs())),
      s_(Eigen::VectorXf::Zero(multigrid.fine_level().dofs())) {}

void LaneVCycle::prepare(const ch07::BlockSparseMatrix& A) {
  reduced_.prepare(A);
  if (!lanes_) return;
  // Each thread fills the row blocks it smooths (the same static share of the same parts).
  with_fine_level([](auto& fine) {
    ch09::for_parts(source_level(fine).rows.part, true,
                    [&](int first, int last) { fine.fill(first, last); });
  });
}

void LaneVCycle::apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) {
  if (!lanes_) {
    reduced_.apply(r, s);
    return;
  }
  const std::vector<int>& part = reduced_.fine_level().source->rows.part;
  ch09::for_parts(part, true, [&](int first, int last) { ch12::convert_rows(r, r_, first, last); });
  with_fine_level([&](auto& fine) { multigrid_.apply(fine, reduced_.coarse_levels(), r_, s_); });
  ch09::for_parts(part, true, [&](int first, int last) { ch12::convert_rows(s_, s, first, last); });
}

}  // namespace fem::ch14
