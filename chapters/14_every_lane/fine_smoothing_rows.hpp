// The definitions of fine_smoothing.hpp's row kernels and counts, for any layout of a level's
// blocks: fine_smoothing.cpp instantiates them for the layouts chapter 14's step runs (in the
// library), row_pairs.cpp for the row pairs, an alternative only the course measures. Include
// it from one of those two files only (its helpers are each file's own).
#pragma once

#include "chapters/14_every_lane/fine_smoothing.hpp"

namespace fem::ch14 {

namespace {

struct Weights {
  float alpha, beta;
  bool restart;  // d = beta D^-1 r (the first step, or from zero)
};

// Row i of the polynomial step from its product `sum` (unused from zero): d = alpha d + beta
// D^-1 (b - sum), out = in + d, with the new d kept in registers (written as `d = ...;
// out = in + d` the compiler must read d back, out might be d: a store and a load on the
// row's chain). The update is one multiply-add and a multiply. Written as `alpha * d + beta
// * t`, the compiler chooses which multiply to fuse with the add from the code around it, so
// that each layout of the blocks rounded it its own way; the multiply-add is spelled out
// (Eigen's pmadd: one fused instruction where the target has FMA, else a multiply and an add
// no compiler can fuse), so that every layout computes the same bits and the stepper may
// choose one by speed alone (it may still round differently from the V-cycle's own generic
// step, which leaves the choice to the compiler).
template <class Blocks>
void update_row(LaneLevel<Blocks>& level, int i, const Eigen::Vector3f& sum, const Weights& w,
                const Eigen::VectorXf& b, const Eigen::VectorXf* in, Eigen::VectorXf& out) {
  Eigen::Vector3f r = b.segment<3>(3 * i);
  if (in) r -= sum;
  auto d = level.vectors.direction.template segment<3>(3 * i);
  const Eigen::Vector3f t = times_inverse_diagonal(level, i, r);
  Eigen::Vector3f next = w.beta * t;
  if (!w.restart)
    for (int j = 0; j < 3; ++j) next[j] = Eigen::internal::pmadd(w.alpha, d[j], next[j]);
  d = next;
  if (in)
    out.segment<3>(3 * i) = in->segment<3>(3 * i) + next;
  else
    out.segment<3>(3 * i) = next;
}

#if defined(EIGEN_VECTORIZE_SSE)
// The update in four lanes on SSE and wider: a vector operation a step instead of three
// scalar ones, the same roundings per lane. Written in Eigen's packets, not in Array4f: on
// an Array4f GCC takes a lane (r[j]) or the first three (head<3>) through the stack, a store
// and loads that wait for it on every row's chain.
using Eigen::internal::Packet4f;

template <int j>
EIGEN_ALWAYS_INLINE Packet4f splat(const Packet4f& v) {
  return _mm_shuffle_ps(v, v, j * 0x55);
}

// The first 3 lanes of v at p: the low 2, then the 3rd.
EIGEN_ALWAYS_INLINE void store3(float* p, const Packet4f& v) {
  _mm_storel_pi(reinterpret_cast<__m64*>(p), v);
  _mm_store_ss(p + 2, _mm_movehl_ps(v, v));
}

// D_i^-1 r as the float level computes it: a sum per column from zero, then (c0 + c1) + c2
// (the same roundings). The inverse diagonals end with a padding block: the third column's
// 4th float exists.
EIGEN_ALWAYS_INLINE Packet4f inverse_times(const float* D, const Packet4f& r) {
  using namespace Eigen::internal;
  const Packet4f zero = pset1<Packet4f>(0.0f);
  const Packet4f c0 = padd(zero, pmul(ploadu<Packet4f>(D), splat<0>(r)));
  const Packet4f c1 = padd(zero, pmul(ploadu<Packet4f>(D + 3), splat<1>(r)));
  const Packet4f c2 = padd(zero, pmul(ploadu<Packet4f>(D + 6), splat<2>(r)));
  return padd(padd(c0, c1), c2);
}

// update_row in four lanes, for every row but the last (whose 4th floats lie past b, in and
// d).
template <class Blocks>
EIGEN_ALWAYS_INLINE void update_row4(LaneLevel<Blocks>& level, int i, const Eigen::Array4f& sum,
                                     const Weights& w, const Eigen::VectorXf& b,
                                     const Eigen::VectorXf* in, Eigen::VectorXf& out) {
  using namespace Eigen::internal;
  Packet4f r = ploadu<Packet4f>(b.data() + 3 * i);
  if (in) r = psub(r, ploadu<Packet4f>(sum.data()));
  const Packet4f t = inverse_times(level.level.smoother.inverse_diagonal[i].data(), r);
  float* d = level.vectors.direction.data() + 3 * i;
  const Packet4f scaled = pmul(pset1<Packet4f>(w.beta), t);
  // The fused multiply-add spelled out, as in update_row (an FMA target's one instruction;
  // without FMA, Eigen's pmadd is a multiply and an add, which no compiler can fuse then).
  const Packet4f next =
      w.restart ? scaled : pmadd(pset1<Packet4f>(w.alpha), ploadu<Packet4f>(d), scaled);
  store3(d, next);
  store3(out.data() + 3 * i, in ? padd(ploadu<Packet4f>(in->data() + 3 * i), next) : next);
}

template <class Blocks>
EIGEN_ALWAYS_INLINE void update(LaneLevel<Blocks>& level, int i, const Eigen::Array4f& sum,
                                const Weights& w, const Eigen::VectorXf& b,
                                const Eigen::VectorXf* in, Eigen::VectorXf& out) {
  if (i + 1 < level.blocks.rows())
    update_row4(level, i, sum, w, b, in, out);
  else
    update_row(level, i, sum.head<3>().matrix(), w, b, in, out);
}
#else
template <class Blocks>
EIGEN_ALWAYS_INLINE void update(LaneLevel<Blocks>& level, int i, const Eigen::Array4f& sum,
                                const Weights& w, const Eigen::VectorXf& b,
                                const Eigen::VectorXf* in, Eigen::VectorXf& out) {
  update_row(level, i, sum.head<3>().matrix(), w, b, in, out);
}
#endif

}  // namespace

template <class Blocks>
void smooth_rows(LaneLevel<Blocks>& level, int k, int first, int last, const Eigen::VectorXf& b,
                 const Eigen::VectorXf* in, Eigen::VectorXf& out) {
  const Weights w{level.smoother.weights[2 * k], level.smoother.weights[2 * k + 1], k == 0 || !in};
  const auto row = [&](int i, const Eigen::Array4f& sum) { update(level, i, sum, w, b, in, out); };
  if (in) {
    level.blocks.for_rows(first, last, in->data(), row);
    return;
  }
  for (int i = first; i < last; ++i) row(i, Eigen::Array4f::Zero());
}

template <class Blocks>
void residual_rows(LaneLevel<Blocks>& level, int first, int last, const Eigen::VectorXf& b,
                   const Eigen::VectorXf& x) {
  auto& residual = level.vectors.residual;
  level.blocks.for_rows(first, last, x.data(), [&](int i, const Eigen::Array4f& sum) {
    residual.template segment<3>(3 * i) = b.segment<3>(3 * i) - sum.head<3>().matrix();
  });
}

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

}  // namespace fem::ch14
