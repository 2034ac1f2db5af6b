// Chapter 12: the products of chapter 10's V-cycle (v_cycle.hpp) on float levels, and the
// conversion of chapter 10's numbers into them (see reduced_v_cycle.hpp). Chapter 10's
// polynomial smoothers and residual run on these products; Gauss-Seidel would be the same
// change once more.
#include "chapters/12_half_the_bytes/reduced_v_cycle.hpp"

#include <stdexcept>
#include <type_traits>

#include "chapters/09_threads/parallel.hpp"
#include "chapters/10_multigrid/v_cycle.hpp"

namespace fem::ch12 {

// Found by chapter 10's V-cycle through its level argument (argument-dependent lookup): so
// in this namespace, not an unnamed one.

// The products of the V-cycle, on float blocks, in padded lanes. Eigen keeps a fixed-size
// vector whose length is no multiple of a packet in scalars (Matrix<float, 3, 1>: three
// scalar multiply-adds per column), so chapter 10's column-by-column form would spend as many
// instructions on a float block as on a double one, and save only bytes. Here a column of R
// rows is loaded as Lanes<R> floats (R = 3: 4, the next column's first float in the last
// lane; R = 6: 8) and costs one vector multiply-add; the extra lanes collect harmless
// products of finite numbers and are dropped. Every array of blocks ends with one padding
// block, so that the last column's extra floats exist. In Real = double the loaded floats
// are widened in registers: memory sees float, the arithmetic is double.
template <int R>
constexpr int Lanes = R == 3 ? 4 : 8;

template <class Real, int R>
using Wide = Eigen::Matrix<Real, Lanes<R>, 1>;

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
  using Column = Eigen::Matrix<float, Lanes<R>, 1>;
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
using ch10::residual;
using ch10::smooth;
using ch10::smoothing_steps;

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

namespace {

template <class Real, int B>
void size_level(ReducedLevel<Real, B>& level, const ch10::Level<B>& source) {
  level.source = &source;
  level.vectors.resize(source.dofs());
  if (source.coarsest) {  // chapter 10's Cholesky factor in double, nothing in float
    level.dense.setZero(source.dofs());
    return;
  }
  // One padding block after each array (add_product reads a few floats past a block's end).
  level.blocks.resize(source.A.column.size() + 1, Eigen::Matrix<float, B, B>::Zero());
  level.smoother.inverse_diagonal.resize(source.nodes() + 1, Eigen::Matrix<float, B, B>::Zero());
  level.P.resize(source.transfer.P.blocks.size() + 1, Eigen::Matrix<float, B, kModes>::Zero());
  level.R.resize(source.transfer.R.blocks.size() + 1, Eigen::Matrix<float, kModes, B>::Zero());
}

}  // namespace

template <class Real>
ReducedVCycle<Real>::ReducedVCycle(ch10::Multigrid& multigrid) : multigrid_(multigrid) {
  if (multigrid.settings().relax.smoother == ch10::Smoother::GaussSeidel)
    throw std::invalid_argument(
        "float V-cycle: the polynomial smoothers only (Chebyshev, Jacobi), not Gauss-Seidel");
  size_level(fine_, multigrid.fine_level());
  coarse_.resize(multigrid.coarse_levels().size());
  for (std::size_t l = 0; l < coarse_.size(); ++l)
    size_level(coarse_[l], multigrid.coarse_levels()[l]);
  r_.setZero(fine_.source->dofs());
  s_.setZero(fine_.source->dofs());
}

// The level's numbers into float, by its row blocks: the matrix and the smoother's inverse
// diagonal every time (the finest level changes every step), the prolongators and the
// weights after a refresh (when a coarse level changed, and P with it on the first).
template <class Real>
template <int B>
void ReducedVCycle<Real>::convert(ReducedLevel<Real, B>& level, bool refreshed, bool collective) {
  const ch10::Level<B>& source = *level.source;
  if (source.coarsest) return;  // solved in double by chapter 10's Cholesky factor
  const ch10::Transfer<B>& transfer = source.transfer;
  ch09::for_parts(source.rows.part, collective, [&](int first, int last) {
    for (int k = source.A.row_start[first]; k < source.A.row_start[last]; ++k)
      level.blocks[k] = source.values[k].template cast<float>();
    for (int i = first; i < last; ++i)
      level.smoother.inverse_diagonal[i] =
          source.smoother.inverse_diagonal[i].template cast<float>();
    if (!refreshed) return;
    for (int m = transfer.P.row_start[first]; m < transfer.P.row_start[last]; ++m)
      level.P[m] = transfer.P.blocks[m].template cast<float>();
  });
  if (!refreshed) return;
  ch09::on_one_thread(collective, [&] {
    // R's rows belong to the coarse level's partition: few blocks, one thread.
    for (std::size_t e = 0; e < transfer.R.blocks.size(); ++e)
      level.R[e] = transfer.R.blocks[e].template cast<float>();
    level.smoother.weights.assign(source.smoother.weights.begin(), source.smoother.weights.end());
  });
}

template <class Real>
void ReducedVCycle<Real>::prepare(const ch07::BlockSparseMatrix& A, const ch09::RowChunks&) {
  multigrid_.factorize(A.blocks);
  // Everything after a refresh, and the first time (a hierarchy factorized before this object
  // existed); read by every thread after factorize's last barrier, written after convert's.
  const bool refreshed = multigrid_.refresh_rule().refreshed() || !converted_;
  convert(fine_, refreshed, true);
  ch09::on_one_thread(true, [&] { converted_ = true; });
  if (!refreshed) return;
  for (auto& level : coarse_) {
    if (level.source->rows.serial)  // chapter 10 factorizes a small level on one thread: so here
      ch09::on_one_thread(true, [&] { convert(level, true, false); });
    else
      convert(level, true, true);
  }
}

template <class Real>
void ReducedVCycle<Real>::apply(const ch09::RowChunks&, const Eigen::VectorXd& r,
                                Eigen::VectorXd& s) {
  multigrid_.refresh_rule().count_cycle();  // the refresh rule counts V-cycles
  if constexpr (std::is_same_v<Real, double>) {
    ch10::v_cycle(fine_, coarse_, 0, r, s, true);
  } else {
    const std::vector<int>& part = fine_.source->rows.part;
    ch09::for_parts(part, true, [&](int first, int last) {
      r_.segment(3 * first, 3 * (last - first)) =
          r.segment(3 * first, 3 * (last - first)).template cast<float>();
    });
    ch10::v_cycle(fine_, coarse_, 0, r_, s_, true);
    ch09::for_parts(part, true, [&](int first, int last) {
      s.segment(3 * first, 3 * (last - first)) =
          s_.segment(3 * first, 3 * (last - first)).template cast<double>();
    });
  }
}

template <class Real>
long long ReducedVCycle<Real>::number_bytes() const {
  // What the source level holds, in float (the padding block left out).
  const auto bytes = [](const auto& level) {
    const auto& source = *level.source;
    if (source.coarsest) return 0LL;
    return static_cast<long long>(sizeof(level.blocks[0]) * source.A.column.size() +
                                  sizeof(level.smoother.inverse_diagonal[0]) * source.nodes() +
                                  sizeof(level.P[0]) * source.transfer.P.blocks.size() +
                                  sizeof(level.R[0]) * source.transfer.R.blocks.size());
  };
  long long total = bytes(fine_);
  for (const auto& level : coarse_) total += bytes(level);
  return total;
}

template class ReducedVCycle<float>;
template class ReducedVCycle<double>;

}  // namespace fem::ch12
