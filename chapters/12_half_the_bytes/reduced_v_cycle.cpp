// Chapter 12: chapter 10's V-cycle on float numbers (see reduced_v_cycle.hpp). The loops are
// chapter 10's (multigrid.cpp: polynomial_step, residual, restrict_rows, prolong_rows, cycle)
// with the blocks read as float; only the polynomial smoothers are here, the ones whose every
// sweep reads the whole level (Gauss-Seidel would be the same change once more).
#include "chapters/12_half_the_bytes/reduced_v_cycle.hpp"

#include <limits>
#include <stdexcept>
#include <type_traits>

#include "chapters/09_threads/parallel.hpp"

namespace fem::ch12 {

namespace {

// body(first, last) on each of the source level's fixed row blocks, shared out by the team
// (chapter 10's for_parts): the same partition, so the same bits for any thread count.
template <class Level, class Body>
void for_parts(const Level& level, bool collective, Body&& body) {
  const std::vector<int>& part = level.source->part;
  const int count = static_cast<int>(part.size()) - 1;
  if (collective) {
    for (const int p : ch09::StaticShare(count)) body(part[p], part[p + 1]);
  } else {
    for (int p = 0; p < count; ++p) body(part[p], part[p + 1]);
  }
}

template <class Body>
void on_one_thread(bool collective, Body&& body) {
  if (collective) {
#pragma omp single
    body();
  } else {
    body();
  }
}

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
EIGEN_ALWAYS_INLINE Eigen::Matrix<Real, B, 1> row_product(const ReducedLevel<Real, B>& level,
                                                          const Real* x, int begin, int end) {
  auto even = Sums<Real, B, B>::Zero(), odd = Sums<Real, B, B>::Zero();
  const int* column = level.source->A.column.data();
  const Eigen::Matrix<float, B, B>* blocks = level.blocks.data();
  int k = begin;
  for (; k + 1 < end; k += 2) {
    add_product(even, blocks[k], x + B * column[k]);
    add_product(odd, blocks[k + 1], x + B * column[k + 1]);
  }
  if (k < end) add_product(even, blocks[k], x + B * column[k]);
  return even.total() + odd.total();
}

template <class Real, int B>
EIGEN_ALWAYS_INLINE Eigen::Matrix<Real, B, 1> times_inverse_diagonal(
    const ReducedLevel<Real, B>& level, int i, const Eigen::Matrix<Real, B, 1>& r) {
  auto out = Sums<Real, B, B>::Zero();
  add_product(out, level.inverse_diagonal[i], r.data());
  return out.total();
}

// Chapter 10's polynomial_step: d = alpha d + beta D^-1 (b - A in), out = in + d.
template <class Real, int B>
void polynomial_step(ReducedLevel<Real, B>& level, int k, int first, int last,
                     const Eigen::Matrix<Real, Eigen::Dynamic, 1>& b,
                     const Eigen::Matrix<Real, Eigen::Dynamic, 1>* in,
                     Eigen::Matrix<Real, Eigen::Dynamic, 1>& out) {
  using Vector = Eigen::Matrix<Real, B, 1>;
  const Real alpha = level.chebyshev[2 * k], beta = level.chebyshev[2 * k + 1];
  const std::vector<int>& row_start = level.source->A.row_start;
  for (int i = first; i < last; ++i) {
    Vector r = b.template segment<B>(B * i);
    if (in) r -= row_product(level, in->data(), row_start[i], row_start[i + 1]);
    auto d = level.direction.template segment<B>(B * i);
    if (k == 0 || !in)
      d = beta * times_inverse_diagonal(level, i, r);
    else
      d = alpha * d + beta * times_inverse_diagonal(level, i, r);
    if (in)
      out.template segment<B>(B * i) = in->template segment<B>(B * i) + d;
    else
      out.template segment<B>(B * i) = d;
  }
}

template <class Real, int B>
void residual(ReducedLevel<Real, B>& level, int first, int last,
              const Eigen::Matrix<Real, Eigen::Dynamic, 1>& b,
              const Eigen::Matrix<Real, Eigen::Dynamic, 1>& x) {
  const std::vector<int>& row_start = level.source->A.row_start;
  for (int i = first; i < last; ++i)
    level.work.template segment<B>(B * i) =
        b.template segment<B>(B * i) - row_product(level, x.data(), row_start[i], row_start[i + 1]);
}

// b_c = P^T r on coarse rows [first, last), fine rows in increasing order.
template <class Real, int B>
void restrict_rows(const ReducedLevel<Real, B>& level, ReducedLevel<Real, kModes>& coarse,
                   int first, int last) {
  const auto& PT = level.source->PT;
  for (int c = first; c < last; ++c) {
    auto sum = Sums<Real, kModes, B>::Zero();
    for (int e = PT.row_start[c]; e < PT.row_start[c + 1]; ++e)
      add_product(sum, level.PT[e], level.work.data() + B * PT.column[e]);
    coarse.b.template segment<kModes>(kModes * c) = sum.total();
  }
}

// y = x + P x_c on rows [first, last).
template <class Real, int B>
void prolong_rows(ReducedLevel<Real, B>& level, const ReducedLevel<Real, kModes>& coarse, int first,
                  int last, const Eigen::Matrix<Real, Eigen::Dynamic, 1>& x) {
  const auto& P = level.source->P;
  for (int i = first; i < last; ++i) {
    auto sum = Sums<Real, B, kModes>::Zero();
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m)
      add_product(sum, level.P[m], coarse.x.data() + kModes * P.column[m]);
    level.y.template segment<B>(B * i) = x.template segment<B>(B * i) + sum.total();
  }
}

template <class Real, int B>
void size_level(ReducedLevel<Real, B>& level, const ch10::Level<B>& source) {
  level.source = &source;
  const Eigen::Index n = source.dofs();
  for (auto* v : {&level.b, &level.x, &level.y, &level.work, &level.direction}) v->setZero(n);
  if (source.coarsest) {  // chapter 10's Cholesky factor in double, nothing in float
    level.dense.setZero(n);
    return;
  }
  // One padding block after each array (add_product reads a few floats past a block's end).
  level.blocks.resize(source.A.column.size() + 1, Eigen::Matrix<float, B, B>::Zero());
  level.inverse_diagonal.resize(source.nodes() + 1, Eigen::Matrix<float, B, B>::Zero());
  level.P.resize(source.P.blocks.size() + 1, Eigen::Matrix<float, B, kModes>::Zero());
  level.PT.resize(source.PT.blocks.size() + 1, Eigen::Matrix<float, kModes, B>::Zero());
}

}  // namespace

template <class Real>
ReducedVCycle<Real>::ReducedVCycle(ch10::Multigrid& multigrid) : multigrid_(multigrid) {
  if (multigrid.settings().smoother == ch10::MultigridSettings::Smoother::GaussSeidel)
    throw std::invalid_argument(
        "float V-cycle: the polynomial smoothers only (Chebyshev, Jacobi), not Gauss-Seidel");
  size_level(fine_, multigrid.fine_level());
  coarse_.resize(multigrid.levels() - 1);
  for (int l = 1; l < multigrid.levels(); ++l)
    size_level(coarse_[l - 1], multigrid.coarse_level(l));
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
  for_parts(level, collective, [&](int first, int last) {
    for (int k = source.A.row_start[first]; k < source.A.row_start[last]; ++k)
      level.blocks[k] = source.values[k].template cast<float>();
    for (int i = first; i < last; ++i)
      level.inverse_diagonal[i] = source.inverse_diagonal[i].template cast<float>();
    if (!refreshed) return;
    for (int m = source.P.row_start[first]; m < source.P.row_start[last]; ++m)
      level.P[m] = source.P.blocks[m].template cast<float>();
  });
  if (!refreshed) return;
  on_one_thread(collective, [&] {
    // P^T's rows belong to the coarse level's partition: few blocks, one thread.
    for (std::size_t e = 0; e < source.PT.blocks.size(); ++e)
      level.PT[e] = source.PT.blocks[e].template cast<float>();
    level.chebyshev.assign(source.chebyshev.begin(), source.chebyshev.end());
  });
}

template <class Real>
void ReducedVCycle<Real>::prepare(const ch07::BlockSparseMatrix& A, const ch09::RowChunks&) {
  multigrid_.prepare(A.blocks);
  // Everything after a refresh, and the first time (a hierarchy prepared before this object
  // existed); read by every thread after prepare's last barrier, written after convert's.
  const bool refreshed = multigrid_.refreshed() || !converted_;
  convert(fine_, refreshed, true);
  on_one_thread(true, [&] { converted_ = true; });
  if (!refreshed) return;
  for (auto& level : coarse_) {
    if (level.source->serial)  // chapter 10 prepares a small level on one thread: so here
      on_one_thread(true, [&] { convert(level, true, false); });
    else
      convert(level, true, true);
  }
}

template <class Real>
void ReducedVCycle<Real>::apply(const ch09::RowChunks&, const Eigen::VectorXd& r,
                                Eigen::VectorXd& s) {
  multigrid_.count_cycle();  // the refresh rule counts V-cycles
  if constexpr (std::is_same_v<Real, double>) {
    cycle(fine_, 0, r, s, true);
  } else {
    for_parts(fine_, true, [&](int first, int last) {
      r_.segment(3 * first, 3 * (last - first)) =
          r.segment(3 * first, 3 * (last - first)).template cast<float>();
    });
    cycle(fine_, 0, r_, s_, true);
    for_parts(fine_, true, [&](int first, int last) {
      s.segment(3 * first, 3 * (last - first)) =
          s_.segment(3 * first, 3 * (last - first)).template cast<double>();
    });
  }
}

// Chapter 10's cycle with a polynomial smoother: pre-smoothing from zero, ping-ponging between
// x and y, the residual restricted, the coarse cycle, the correction prolonged, post-smoothing.
template <class Real>
template <int B>
void ReducedVCycle<Real>::cycle(ReducedLevel<Real, B>& level, std::size_t next, const Vector& b,
                                Vector& out, bool collective) {
  const ch10::Level<B>& source = *level.source;
  if (collective && source.serial) {
    on_one_thread(true, [&] { cycle(level, next, b, out, false); });
    return;
  }
  if (source.coarsest) {
    // At most max_coarse_dofs unknowns: the dense solve stays in double, in chapter 10's factor.
    on_one_thread(collective, [&] {
      level.dense = b.template cast<double>();
      if (source.cholesky.info() == Eigen::Success)
        source.cholesky.solveInPlace(level.dense);
      else
        level.dense.setConstant(std::numeric_limits<double>::quiet_NaN());
      out = level.dense.template cast<Real>();
    });
    return;
  }
  const int steps = static_cast<int>(level.chebyshev.size()) / 2;
  const Vector* current = nullptr;
  for (int k = 0; k < steps; ++k) {
    Vector& target = k % 2 == 0 ? level.x : level.y;
    for_parts(level, collective, [&](int first, int last) {
      polynomial_step(level, k, first, last, b, current, target);
    });
    current = &target;
  }
  for_parts(level, collective,
            [&](int first, int last) { residual(level, first, last, b, *current); });
  ReducedLevel<Real, kModes>& coarse = coarse_[next];
  for_parts(coarse, collective,
            [&](int first, int last) { restrict_rows(level, coarse, first, last); });
  cycle(coarse, next + 1, coarse.b, coarse.x, collective);
  for_parts(level, collective,
            [&](int first, int last) { prolong_rows(level, coarse, first, last, *current); });
  current = &level.y;
  for (int k = 0; k < steps; ++k) {
    Vector& target = (steps - k) % 2 == 1 ? out : level.work;
    for_parts(level, collective, [&](int first, int last) {
      polynomial_step(level, k, first, last, b, current, target);
    });
    current = &target;
  }
}

template <class Real>
long long ReducedVCycle<Real>::number_bytes() const {
  // What the source level holds, in float (the padding block left out).
  const auto bytes = [](const auto& level) {
    const auto& source = *level.source;
    if (source.coarsest) return 0LL;
    return static_cast<long long>(sizeof(level.blocks[0]) * source.A.column.size() +
                                  sizeof(level.inverse_diagonal[0]) * source.nodes() +
                                  sizeof(level.P[0]) * source.P.blocks.size() +
                                  sizeof(level.PT[0]) * source.PT.blocks.size());
  };
  long long total = bytes(fine_);
  for (const auto& level : coarse_) total += bytes(level);
  return total;
}

template class ReducedVCycle<float>;
template class ReducedVCycle<double>;

}  // namespace fem::ch12
