#include "chapters/14_every_lane/fine_smoothing.hpp"

#include "chapters/10_multigrid/v_cycle.hpp"

namespace fem::ch14 {

// The lanes' level brings every kernel the V-cycle calls (a coarse level below it is the
// float hierarchy's).
static_assert(ch10::check_level_kernels<LaneFineLevel, CoarseFloatLevel, Eigen::VectorXf>());

// The V-cycle's polynomial step (d = alpha d + beta D^-1 (b - A in), out = in + d) with the
// new d kept in registers: written as `d = ...; out = in + d`, the compiler must read d back
// from memory (out might be d), a store and a load on every row's chain.
void smooth_rows(LaneFineLevel& level, int k, int first, int last, const Eigen::VectorXf& b,
                 const Eigen::VectorXf* in, Eigen::VectorXf& out) {
  const float alpha = level.smoother.weights[2 * k], beta = level.smoother.weights[2 * k + 1];
  const bool restart = k == 0 || !in;
  for (int i = first; i < last; ++i) {
    Eigen::Vector3f r = b.segment<3>(3 * i);
    if (in) r -= level.blocks.row_product(i, in->data());
    auto d = level.vectors.direction.segment<3>(3 * i);
    const Eigen::Vector3f t = times_inverse_diagonal(level, i, r);
    const Eigen::Vector3f next =
        restart ? Eigen::Vector3f(beta * t) : Eigen::Vector3f(alpha * d + beta * t);
    d = next;
    if (in)
      out.segment<3>(3 * i) = in->segment<3>(3 * i) + next;
    else
      out.segment<3>(3 * i) = next;
  }
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
