// Chapter 12's kernels of the V-cycle on float levels: the products in padded lanes, the
// restriction, the prolongation and the coarsest solve, found by chapter 10's V-cycle
// (v_cycle.hpp) through the level argument (argument-dependent lookup). In a header so that
// a later chapter can run its own cycle on the same levels.
#pragma once

#include <Eigen/Core>
#include <type_traits>

#include "chapters/10_multigrid/smoothers.hpp"
#include "chapters/12_half_the_bytes/reduced_v_cycle.hpp"

namespace fem::ch12 {

// Found by chapter 10's V-cycle through its level argument (argument-dependent lookup): so
// in this namespace, not an unnamed one.

// The products of the V-cycle, on float blocks, in padded lanes. Eigen keeps a fixed-size
// vector whose length is no multiple of a packet in scalars (Matrix<float, 3, 1>: three
// scalar multiply-adds per column), so chapter 10's column-by-column form would spend as many
// instructions on a float block as on a double one, and save only bytes. Here a column of R
// rows is loaded as kPaddedColumn<R> floats (R = 3: 4, the next column's first float in the last
// lane; R = 6: 8) and costs one vector multiply-add; the extra lanes collect harmless
// products of finite numbers and are dropped. Every array of blocks ends with one padding
// block, so that the last column's extra floats exist. In Real = double the loaded floats
// are widened in registers: memory sees float, the arithmetic is double.
template <int R>
constexpr int kPaddedColumn = R == 3 ? 4 : 8;

template <class Real, int R>
using Wide = Eigen::Matrix<Real, kPaddedColumn<R>, 1>;

// Partial sums of a product, in float one per block column: a block's columns then add into
// independent registers. With one sum, the C multiply-adds of a block form a chain in which
// each waits for the last (4 cycles each on current x86 cores) while the core could start two
// per cycle: the products of a cache-resident level are bound by that latency, not by bytes.
// In double a column of Wide takes twice the registers, and C sums of them spill (AVX2 has 16
// vector registers): one sum there.
template <class Real, int R, int C>
struct Sums {
  static constexpr int kSplit = std::is_same_v<Real, float> ? C : 1;
  Wide<Real, R> column[kSplit];

  static Sums Zero() {
    Sums s;
    for (auto& c : s.column) c.setZero();
    return s;
  }
  Wide<Real, R>& of(int j) { return column[j % kSplit]; }  // block column j's sum
  Eigen::Matrix<Real, R, 1> total() const {
    Wide<Real, R> sum = column[0];
    for (int j = 1; j < kSplit; ++j) sum += column[j];
    return sum.template head<R>();
  }
};

template <class Real, int R, int C>
EIGEN_ALWAYS_INLINE void add_product(Sums<Real, R, C>& sums, const Eigen::Matrix<float, R, C>& M,
                                     const Real* x) {
  using Column = Eigen::Matrix<float, kPaddedColumn<R>, 1>;
  for (int j = 0; j < C; ++j)
    sums.of(j) += Eigen::Map<const Column>(M.data() + R * j).template cast<Real>() * x[j];
}

// sum of A_k x_(column k) over the blocks [begin, end) of a row: 2 B independent sums (two
// blocks at a time, as chapter 10's row_product, and a sum per block column).
template <class Real, int B>
EIGEN_ALWAYS_INLINE Eigen::Matrix<Real, B, 1> row_product(
    const ReducedLevel<Real, B>& level, const Eigen::Matrix<Real, Eigen::Dynamic, 1>& x, int begin,
    int end) {
  auto even = Sums<Real, B, B>::Zero(), odd = Sums<Real, B, B>::Zero();
  const int* column = level.source->A.column.data();
  const Eigen::Matrix<float, B, B>* blocks = level.blocks.data();
  int k = begin;
  for (; k + 1 < end; k += 2) {
    add_product(even, blocks[k], x.data() + B * column[k]);
    add_product(odd, blocks[k + 1], x.data() + B * column[k + 1]);
  }
  if (k < end) add_product(even, blocks[k], x.data() + B * column[k]);
  return even.total() + odd.total();
}

// D_i^-1 r, for chapter 10's polynomial_step (its smooth and residual serve this level).
template <class Real, int B, class Rhs>
EIGEN_ALWAYS_INLINE Eigen::Matrix<Real, B, 1> times_inverse_diagonal(
    const ReducedLevel<Real, B>& level, int i, const Rhs& r) {
  auto out = Sums<Real, B, B>::Zero();
  add_product(out, level.smoother.inverse_diagonal[i], r.data());
  return out.total();
}

// b_c = R r on coarse rows [first, last), fine rows in increasing order.
template <class Real, int B>
void restrict_rows(const ReducedLevel<Real, B>& level, ReducedLevel<Real, kModes>& coarse,
                   int first, int last) {
  const auto& R = level.source->transfer.R;
  for (int c = first; c < last; ++c) {
    auto sum = Sums<Real, kModes, B>::Zero();
    for (int e = R.row_start[c]; e < R.row_start[c + 1]; ++e)
      add_product(sum, level.R[e], level.vectors.residual.data() + B * R.column[e]);
    coarse.vectors.b.template segment<kModes>(kModes * c) = sum.total();
  }
}

// y = x + P x_c on rows [first, last).
template <class Real, int B>
void prolong_rows(ReducedLevel<Real, B>& level, const ReducedLevel<Real, kModes>& coarse, int first,
                  int last, const Eigen::Matrix<Real, Eigen::Dynamic, 1>& x) {
  const auto& P = level.source->transfer.P;
  for (int i = first; i < last; ++i) {
    auto sum = Sums<Real, B, kModes>::Zero();
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m)
      add_product(sum, level.P[m], coarse.vectors.x.data() + kModes * P.column[m]);
    level.vectors.y.template segment<B>(B * i) = x.template segment<B>(B * i) + sum.total();
  }
}

// At most max_coarse_dofs unknowns: the dense solve stays in double, in chapter 10's factor.
template <class Real, int B>
void solve_coarsest(ReducedLevel<Real, B>& level, const Eigen::Matrix<Real, Eigen::Dynamic, 1>& b,
                    Eigen::Matrix<Real, Eigen::Dynamic, 1>& out) {
  level.dense = b.template cast<double>();
  ch10::solve_in_place(level.source->coarsest_solve, level.dense);
  out = level.dense.template cast<Real>();
}

}  // namespace fem::ch12
