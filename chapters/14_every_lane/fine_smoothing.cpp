#include "chapters/14_every_lane/fine_smoothing.hpp"

#include "chapters/10_multigrid/v_cycle.hpp"

namespace fem::ch14 {

// The lanes' level brings every kernel the V-cycle calls (a coarse level below it is the
// float hierarchy's).
static_assert(ch10::check_level_kernels<LaneFineLevel, CoarseFloatLevel, Eigen::VectorXf>());
static_assert(ch10::check_level_kernels<RowPairFineLevel, CoarseFloatLevel, Eigen::VectorXf>());

namespace {

struct Weights {
  float alpha, beta;
  bool restart;  // d = beta D^-1 r (the first step, or from zero)
};

// Row i of the polynomial step from its product `sum` (unused from zero): d = alpha d + beta
// D^-1 (b - sum), out = in + d, with the new d kept in registers (written as `d = ...;
// out = in + d` the compiler must read d back, out might be d: a store and a load on the
// row's chain). The update is one multiply-add and a multiply: which multiply the compiler
// fuses depends on the code around it, so it may round differently from the V-cycle's own.
template <class Blocks>
void update_row(LaneLevel<Blocks>& level, int i, const Eigen::Vector3f& sum, const Weights& w,
                const Eigen::VectorXf& b, const Eigen::VectorXf* in, Eigen::VectorXf& out) {
  Eigen::Vector3f r = b.segment<3>(3 * i);
  if (in) r -= sum;
  auto d = level.vectors.direction.template segment<3>(3 * i);
  const Eigen::Vector3f t = times_inverse_diagonal(level, i, r);
  const Eigen::Vector3f next =
      w.restart ? Eigen::Vector3f(w.beta * t) : Eigen::Vector3f(w.alpha * d + w.beta * t);
  d = next;
  if (in)
    out.segment<3>(3 * i) = in->segment<3>(3 * i) + next;
  else
    out.segment<3>(3 * i) = next;
}

using Piece = Eigen::Map<const Eigen::Array4f>;  // a node's 3 floats and the next one
using Store = Eigen::Map<Eigen::Array3f>;

// D_i^-1 r in four lanes as the float level computes it (a sum per column from zero, then
// (c0 + c1) + c2: the same roundings); the lanes past the third are dropped. The inverse
// diagonals end with a padding block: the third column's 4th float exists.
EIGEN_ALWAYS_INLINE Eigen::Array4f inverse_times(const FloatLevel& level, int i,
                                                 const Eigen::Array4f& r) {
  const float* D = level.smoother.inverse_diagonal[i].data();
  Eigen::Array4f c0 = Eigen::Array4f::Zero(), c1 = c0, c2 = c0;
  c0 += Piece(D) * r[0];
  c1 += Piece(D + 3) * r[1];
  c2 += Piece(D + 6) * r[2];
  return (c0 + c1) + c2;
}

// update_row in four lanes, for every row but the last (whose 4th floats lie past b, in and
// d): a vector operation a step instead of three scalar ones, the same roundings per lane.
template <class Blocks>
EIGEN_ALWAYS_INLINE void update_row4(LaneLevel<Blocks>& level, int i, const Eigen::Array4f& sum,
                                     const Weights& w, const Eigen::VectorXf& b,
                                     const Eigen::VectorXf* in, Eigen::VectorXf& out) {
  Eigen::Array4f r = Piece(b.data() + 3 * i);
  if (in) r -= sum;
  const Eigen::Array4f t = inverse_times(level.level, i, r);
  float* d = level.vectors.direction.data() + 3 * i;
  const Eigen::Array4f next =
      w.restart ? Eigen::Array4f(w.beta * t) : Eigen::Array4f(w.alpha * Piece(d) + w.beta * t);
  Store{d} = next.head<3>();
  if (in)
    Store{out.data() + 3 * i} = (Piece(in->data() + 3 * i) + next).head<3>();
  else
    Store{out.data() + 3 * i} = next.head<3>();
}

}  // namespace

template <class Blocks>
void smooth_rows(LaneLevel<Blocks>& level, int k, int first, int last, const Eigen::VectorXf& b,
                 const Eigen::VectorXf* in, Eigen::VectorXf& out) {
  const Weights w{level.smoother.weights[2 * k], level.smoother.weights[2 * k + 1], k == 0 || !in};
  const int last_row = level.blocks.rows() - 1;
  const auto update = [&](int i, const Eigen::Array4f& sum) {
    if (i < last_row)
      update_row4(level, i, sum, w, b, in, out);
    else
      update_row(level, i, sum.head<3>().matrix(), w, b, in, out);
  };
  if (in) {
    level.blocks.for_rows(first, last, in->data(), update);
    return;
  }
  for (int i = first; i < last; ++i) update(i, Eigen::Array4f::Zero());
}

template <class Blocks>
void residual_rows(LaneLevel<Blocks>& level, int first, int last, const Eigen::VectorXf& b,
                   const Eigen::VectorXf& x) {
  auto& residual = level.vectors.residual;
  level.blocks.for_rows(first, last, x.data(), [&](int i, const Eigen::Array4f& sum) {
    residual.template segment<3>(3 * i) = b.segment<3>(3 * i) - sum.head<3>().matrix();
  });
}

template void smooth_rows(LaneFineLevel&, int, int, int, const Eigen::VectorXf&,
                          const Eigen::VectorXf*, Eigen::VectorXf&);
template void smooth_rows(RowPairFineLevel&, int, int, int, const Eigen::VectorXf&,
                          const Eigen::VectorXf*, Eigen::VectorXf&);
template void residual_rows(LaneFineLevel&, int, int, const Eigen::VectorXf&,
                            const Eigen::VectorXf&);
template void residual_rows(RowPairFineLevel&, int, int, const Eigen::VectorXf&,
                            const Eigen::VectorXf&);

namespace {

// A float vector of the level, and its inverse diagonal (3x3 float blocks).
template <class Blocks>
double vector_bytes(const Blocks& A) {
  return 3.0 * sizeof(float) * A.rows();
}
template <class Blocks>
double inverse_bytes(const Blocks& A) {
  return 9.0 * sizeof(float) * A.rows();
}

}  // namespace

// A smoothing step after the first: the lanes and the inverse diagonal read, x, b and the
// direction read, the direction written back and the output written fresh (allocating its
// lines). Per block 18 flops, per row the inverse diagonal's 18 and the update's 18: the
// useful ones, not the padding lanes'.
template <class Blocks>
PhaseWork LaneLevel<Blocks>::smoothing_work() const {
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
template <class Blocks>
PhaseWork LaneLevel<Blocks>::residual_work() const {
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

template struct LaneLevel<PaddedFloatBlocks>;
template struct LaneLevel<RowPairBlocks>;

}  // namespace fem::ch14
