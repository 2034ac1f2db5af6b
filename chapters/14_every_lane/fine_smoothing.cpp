#include "chapters/14_every_lane/fine_smoothing.hpp"

#include "chapters/10_multigrid/v_cycle.hpp"

namespace fem::ch14 {

// The lanes' level brings every kernel the V-cycle calls (a coarse level below it is the
// float hierarchy's).
static_assert(ch10::check_level_kernels<LaneFineLevel, CoarseFloatLevel, Eigen::VectorXf>());

void smooth_rows(LaneFineLevel& level, int k, int first, int last, const Eigen::VectorXf& b,
                 const Eigen::VectorXf* in, Eigen::VectorXf& out) {
  ch10::smooth(level, k, first, last, b, in, out, true);
}

void residual_rows(LaneFineLevel& level, int first, int last, const Eigen::VectorXf& b,
                   const Eigen::VectorXf& x) {
  ch10::residual(level, first, last, b, x);
}

namespace {

// A float vector of the level, and its inverse diagonal (3x3 float blocks).
double vector_bytes(const PairedBlocks<float>& A) { return 3.0 * sizeof(float) * A.rows(); }
double inverse_bytes(const PairedBlocks<float>& A) { return 9.0 * sizeof(float) * A.rows(); }

}  // namespace

// A smoothing step after the first: the lanes and the inverse diagonal read, x, b and the
// direction read, the direction written back and the output written fresh (allocating its
// lines). Per block 18 flops, per row the inverse diagonal's 18 and the update's 18: the
// useful ones, not the padding lanes'.
PhaseWork LaneFineLevel::smoothing_work() const {
  const double v = vector_bytes(blocks), rows = blocks.rows();
  PhaseWork w;
  w.phase = "smoothing step";
  w.bytes_read = blocks.bytes() + inverse_bytes(blocks) + 3 * v;
  w.bytes_written = 2 * v;
  w.bytes_allocated = v;
  w.flops_float = 18.0 * (double(blocks.blocks()) + rows) + 18.0 * rows;
  w.working_set = blocks.bytes() + inverse_bytes(blocks) + 4 * v;
  return w;
}

// The residual: the lanes, x and b read, the residual written fresh; 18 flops a block, 3 a row.
PhaseWork LaneFineLevel::residual_work() const {
  const double v = vector_bytes(blocks);
  PhaseWork w;
  w.phase = "residual";
  w.bytes_read = blocks.bytes() + 2 * v;
  w.bytes_written = v;
  w.bytes_allocated = v;
  w.flops_float = 18.0 * double(blocks.blocks()) + 3.0 * blocks.rows();
  w.working_set = blocks.bytes() + 3 * v;
  return w;
}

}  // namespace fem::ch14
