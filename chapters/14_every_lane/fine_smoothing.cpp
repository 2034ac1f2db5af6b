#include "chapters/14_every_lane/fine_smoothing.hpp"

#include "chapters/10_multigrid/v_cycle.hpp"
#include "chapters/14_every_lane/fine_smoothing_rows.hpp"

namespace fem::ch14 {

// The lanes' level brings every kernel the V-cycle calls (a coarse level below it is the
// float hierarchy's).
static_assert(ch10::check_level_kernels<LaneFineLevel, CoarseFloatLevel, Eigen::VectorXf>());
static_assert(ch10::check_level_kernels<PackedFineLevel, CoarseFloatLevel, Eigen::VectorXf>());

template void smooth_rows(LaneFineLevel&, int, int, int, const Eigen::VectorXf&,
                          const Eigen::VectorXf*, Eigen::VectorXf&);
template void smooth_rows(PackedFineLevel&, int, int, int, const Eigen::VectorXf&,
                          const Eigen::VectorXf*, Eigen::VectorXf&);
template void residual_rows(PackedFineLevel&, int, int, const Eigen::VectorXf&,
                            const Eigen::VectorXf&);
template void residual_rows(LaneFineLevel&, int, int, const Eigen::VectorXf&,
                            const Eigen::VectorXf&);

template struct LaneLevel<PaddedFloatBlocks>;
template struct LaneLevel<PackedFloatBlocks>;

}  // namespace fem::ch14
