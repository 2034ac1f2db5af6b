// Chapter 10: the prolongator, tentative and smoothed (Vanek, Mandel & Brezina 1996; PyAMG's
// fit_candidates and jacobi_prolongation_smoother). T maps an aggregate's modes onto its nodes;
// P = (I - w D^-1 A) T widens each aggregate's basis by one ring of neighbours, so that the
// coarse space represents smooth errors with less energy. Its pattern and tables are built at
// set-up, its numbers on the first refresh; the restriction R = P^T follows every change of P.
// And the two transfers of the V-cycle: restriction and prolongation.
#pragma once

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <vector>

#include "chapters/10_multigrid/aggregation.hpp"
#include "chapters/10_multigrid/level.hpp"

namespace fem::ch10 {

// T per aggregate: the aggregate's modes N orthonormalized, T = N V L^-1/2 from N^T N = V L V^T,
// and the coarse node's modes L^1/2 V^T (so that T times them is N). A mode whose eigenvalue
// is negligible (all nodes fixed, a collinear aggregate, 3 modes only) gets a zero column:
// its coarse row and column of P^T A P are zero and receive the identity instead (missing).
template <int B>
void tentative_prolongator(const std::vector<Eigen::Matrix<double, B, kModes>>& modes,
                           const std::vector<int>& aggregate, int count,
                           std::vector<Eigen::Matrix<double, B, kModes>>& tentative,
                           std::vector<Eigen::Matrix<double, kModes, kModes>>& coarse_modes,
                           std::vector<Eigen::Matrix<double, kModes, 1>>& missing) {
  using Matrix6d = Eigen::Matrix<double, kModes, kModes>;
  using Vector6d = Eigen::Matrix<double, kModes, 1>;
  std::vector<Matrix6d> gram(count, Matrix6d::Zero());
  for (std::size_t i = 0; i < aggregate.size(); ++i)
    gram[aggregate[i]].noalias() += modes[i].transpose() * modes[i];
  std::vector<Matrix6d> map(count);
  coarse_modes.resize(count);
  missing.resize(count);
  for (int a = 0; a < count; ++a) {
    const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(gram[a]);
    const Vector6d lambda = eigen.eigenvalues();
    const double largest = lambda.maxCoeff();
    for (int k = 0; k < kModes; ++k) {
      const bool kept = largest > 0.0 && lambda[k] > 1e-10 * largest;
      const double s = kept ? std::sqrt(lambda[k]) : 0.0;
      map[a].col(k) = kept ? Vector6d(eigen.eigenvectors().col(k) / s) : Vector6d::Zero();
      coarse_modes[a].row(k) = s * eigen.eigenvectors().col(k).transpose();
      missing[a][k] = kept ? 0.0 : 1.0;
    }
  }
  tentative.resize(aggregate.size());
  for (std::size_t i = 0; i < aggregate.size(); ++i)
    tentative[i].noalias() = modes[i] * map[aggregate[i]];
}

// The smoothed prolongator has the pattern of A T (row i: the aggregates of i's neighbours);
// T has one block per row, at (i, aggregate[i]); smoothing_target says where each product A_k T
// lands. R = P^T's rows list P's blocks by coarse row, fine rows in increasing order.
template <int B>
void build_prolongator_pattern(Level<B>& fine, const std::vector<int>& aggregate, int count,
                               bool smooth) {
  const auto& A = fine.A;
  Transfer<B>& transfer = fine.transfer;
  const int n = fine.nodes();
  Rows rows(n);
  for (int i = 0; i < n; ++i) {
    if (smooth)
      for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
        rows[i].push_back(aggregate[A.column[k]]);
    else
      rows[i].push_back(aggregate[i]);
    sort_unique(rows[i]);
  }
  transfer.P = BlockCsr<B, kModes>(rows);
  transfer.tentative_block.resize(n);
  for (int i = 0; i < n; ++i) transfer.tentative_block[i] = transfer.P.find(i, aggregate[i]);
  transfer.smoothing_target.clear();
  if (smooth)
    for (int i = 0; i < n; ++i)
      for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
        transfer.smoothing_target.push_back(transfer.P.find(i, aggregate[A.column[k]]));
  Rows transposed(count), source(count);
  for (int i = 0; i < n; ++i)
    for (int m = transfer.P.row_start[i]; m < transfer.P.row_start[i + 1]; ++m) {
      transposed[transfer.P.column[m]].push_back(i);
      source[transfer.P.column[m]].push_back(m);
    }
  transfer.R = BlockCsr<kModes, B>(transposed);
  transfer.restriction_source.clear();
  for (const auto& s : source)
    transfer.restriction_source.insert(transfer.restriction_source.end(), s.begin(), s.end());
  fine.galerkin.p_transposed.resize(transfer.restriction_source.size());
}

// R's blocks from P's, in R's row order (the restriction and the Galerkin product then stream
// through them as an SpMV does), and P's transposed in P's order (for A P, row by row). After
// every change of P (set-up, smoothing).
template <int B>
void transpose_prolongator(Level<B>& level) {
  Transfer<B>& transfer = level.transfer;
  for (std::size_t e = 0; e < transfer.restriction_source.size(); ++e)
    transfer.R.blocks[e] = transfer.P.blocks[transfer.restriction_source[e]].transpose();
  for (std::size_t m = 0; m < transfer.P.blocks.size(); ++m)
    level.galerkin.p_transposed[m] = transfer.P.blocks[m].transpose();
}

// P = T until it is smoothed.
template <int B>
void set_tentative(Level<B>& level,
                   const std::vector<Eigen::Matrix<double, B, kModes>>& tentative) {
  Transfer<B>& transfer = level.transfer;
  for (auto& block : transfer.P.blocks) block.setZero();
  for (int i = 0; i < level.nodes(); ++i)
    transfer.P.blocks[transfer.tentative_block[i]] = tentative[i];
  transpose_prolongator(level);
}

// P = T - w D^-1 (A T) on P's pattern; A T has one product per block of A because T has one
// block per row. One thread: on the first refresh only (or every one, update_prolongator).
template <int B>
void smooth_prolongator(Level<B>& level,
                        const std::vector<Eigen::Matrix<double, B, kModes>>& tentative) {
  auto& P = level.transfer.P;
  const auto& A = level.A;
  for (auto& block : P.blocks) block.setZero();
  for (int i = 0; i < level.nodes(); ++i)
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
      P.blocks[level.transfer.smoothing_target[k]].noalias() +=
          level.values[k] * tentative[A.column[k]];
  for (int i = 0; i < level.nodes(); ++i) {
    const Eigen::Matrix<double, B, B> scaled =
        -level.transfer.omega * level.values[level.diagonal[i]].inverse();
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m) {
      const Eigen::Matrix<double, B, kModes> at = P.blocks[m];
      P.blocks[m].noalias() = scaled * at;
    }
    P.blocks[level.transfer.tentative_block[i]] += tentative[i];
  }
  transpose_prolongator(level);
}

// ---- the transfers of the V-cycle ---------------------------------------------------------

// b_c = R r on the coarse rows [first, last): each coarse row sums over its column of P,
// fine rows in increasing order.
template <int B>
void restrict_rows(const Level<B>& level, Level<kModes>& coarse, int first, int last) {
  const auto& R = level.transfer.R;
  for (int c = first; c < last; ++c) {
    Eigen::Matrix<double, kModes, 1> sum = Eigen::Matrix<double, kModes, 1>::Zero();
    for (int e = R.row_start[c]; e < R.row_start[c + 1]; ++e)
      add_product(sum, R.blocks[e], level.vectors.residual.data() + B * R.column[e]);
    coarse.vectors.b.template segment<kModes>(kModes * c) = sum;
  }
}

// y = x + P x_c on rows [first, last) (x and y may be the same vector: each row reads its own).
template <int B>
void prolong_rows(Level<B>& level, const Level<kModes>& coarse, int first, int last,
                  const Eigen::VectorXd& x) {
  const auto& P = level.transfer.P;
  for (int i = first; i < last; ++i) {
    Eigen::Matrix<double, B, 1> sum = x.template segment<B>(B * i);
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m)
      add_product(sum, P.blocks[m], coarse.vectors.x.data() + kModes * P.column[m]);
    level.vectors.y.template segment<B>(B * i) = sum;
  }
}

}  // namespace fem::ch10
