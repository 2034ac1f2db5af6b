// Chapter 12: the products of chapter 10's V-cycle (v_cycle.hpp) on float levels, and the
// conversion of chapter 10's numbers into them (see reduced_v_cycle.hpp). Chapter 10's
// polynomial smoothers and residual run on these products; Gauss-Seidel would be the same
// change once more.
#include "chapters/12_half_the_bytes/reduced_v_cycle.hpp"

#include <stdexcept>
#include <type_traits>

#include "chapters/09_threads/parallel.hpp"
#include "chapters/12_half_the_bytes/reduced_kernels.hpp"

namespace fem::ch12 {

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
void ReducedVCycle<Real>::prepare(const ch07::BlockSparseMatrix& A) {
  multigrid_.factorize(A.blocks);
  // Everything after a refresh, and the first time (a hierarchy factorized before this object
  // existed); read by every thread after factorize's last barrier, written after convert's.
  multigrid_.for_factorized_levels(
      fine_, coarse_, !converted_.load(std::memory_order_relaxed),
      [&](auto& level, bool collective, bool refreshed) { convert(level, refreshed, collective); });
  ch09::on_one_thread(true, [&] { converted_.store(true, std::memory_order_relaxed); });
}

template <class Real>
void ReducedVCycle<Real>::apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) {
  if constexpr (std::is_same_v<Real, double>) {
    multigrid_.apply(fine_, coarse_, r, s);
  } else {
    const std::vector<int>& part = fine_.source->rows.part;
    ch09::for_parts(part, true, [&](int first, int last) { convert_rows(r, r_, first, last); });
    multigrid_.apply(fine_, coarse_, r_, s_);
    ch09::for_parts(part, true, [&](int first, int last) { convert_rows(s_, s, first, last); });
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
