#include "chapters/14_every_lane/row_pairs.hpp"

#include <algorithm>

#include "chapters/10_multigrid/v_cycle.hpp"
#include "chapters/14_every_lane/fine_smoothing_rows.hpp"

namespace fem::ch14 {

// Rows paired from each part's first; per pair, as many steps as its longer row has pairs of
// blocks, each step's four x pieces (a padding block's: node 0's, read and multiplied by
// zero) and whether one of them is the last node's.
RowPairBlocks::RowPairBlocks(const ch07::BlockCsr<3, 3>& pattern, const std::vector<int>& part)
    : row_start_(pattern.row_start),
      group_(pattern.block_rows(), -1),
      last_x_offset_(3 * (pattern.block_rows() - 1)) {
  const auto count = [&](int row) { return row_start_[row + 1] - row_start_[row]; };
  for (std::size_t p = 0; p + 1 < part.size(); ++p)
    for (int i = part[p]; i < part[p + 1]; i += 2) {
      const bool partner = i + 1 < part[p + 1];
      const int counts[2] = {count(i), partner ? count(i + 1) : 0};
      const int steps = (std::max(counts[0], counts[1]) + 1) / 2;
      group_[i] = static_cast<int>(step_start_.size()) - 1;
      for (int s = 0; s < steps; ++s) {
        bool end = false;
        for (int piece = 0; piece < 4; ++piece) {
          const int r = piece / 2, index = 2 * s + piece % 2;
          const int offset = index < counts[r] ? 3 * pattern.column[row_start_[i + r] + index] : 0;
          x_offset_.push_back(offset);
          end = end || offset == last_x_offset_;
        }
        at_end_.push_back(end);
      }
      step_start_.push_back(step_start_.back() + steps);
    }
  values_.assign(std::size_t(kStep) * step_start_.back(), 0.0f);
}

double RowPairBlocks::bytes() const {
  return double(values_.size()) * sizeof(float) +
         double(x_offset_.size() + step_start_.size() + group_.size()) * sizeof(int) +
         double(at_end_.size());
}

// The row pairs' level brings every kernel the V-cycle calls, as the step's layouts do
// (fine_smoothing.cpp).
static_assert(ch10::check_level_kernels<RowPairFineLevel, CoarseFloatLevel, Eigen::VectorXf>());

template void smooth_rows(RowPairFineLevel&, int, int, int, const Eigen::VectorXf&,
                          const Eigen::VectorXf*, Eigen::VectorXf&);
template void residual_rows(RowPairFineLevel&, int, int, const Eigen::VectorXf&,
                            const Eigen::VectorXf&);
template struct LaneLevel<RowPairBlocks>;

}  // namespace fem::ch14
