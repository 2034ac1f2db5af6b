// Chapter 10: one level of the hierarchy, as the V-cycle and prepare see it after set-up: its
// matrix, the operators to the next level with their symbolic tables, its smoother's numbers,
// its fixed row blocks and its work vectors, each a struct of its own. Nothing here is set-up
// data: the aggregates, the graphs, the near-null-space modes and the tentative prolongator
// live in the Coarsening (coarsening.hpp), which the hierarchy drops once it has built P.
//
// Also the level's block kernels: the products of small fixed-size blocks that every stage's
// loops are made of.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/09_threads/parallel.hpp"

namespace fem::ch10 {

// The hierarchy's matrices are chapter 07's block compressed rows, with 6x6 blocks on the
// aggregates and 3x6 blocks in the prolongators.
using ch07::BlockCsr;

// Every coarse unknown is one aggregate of nodes carrying 6 near-null-space modes.
constexpr int kModes = 6;

// The fixed row blocks of every level: at most max_blocks blocks of at least block_rows rows
// of 3x3 blocks (a quarter as many rows of 6x6), equal in stored blocks. They are the
// Gauss-Seidel smoother's blocks and the unit of work that threads share out; a function of
// the mesh, never of the thread count. 1 block: sequential Gauss-Seidel on one thread.
struct RowBlockSettings {
  int max_blocks = 64;
  int block_rows = 32;
  // A level with fewer rows than this runs (with all levels below it) on one thread: there a
  // barrier costs more than the work it shares out.
  int serial_rows = 0;
};

// A level's fixed row blocks: block p holds rows part[p] .. part[p+1]-1. Per row, its blocks
// with a column inside the row's own block: inner_begin[i] .. inner_end[i]-1 (columns are
// sorted, so that range is contiguous).
struct RowBlocks {
  std::vector<int> part, inner_begin, inner_end;
  bool serial = false;  // run on one thread (serial_rows)
  int count() const { return static_cast<int>(part.size()) - 1; }
};

// The operators from a level to the next: P and the restriction R = P^T, with the tables
// that rebuild P from T when it is smoothed.
template <int B>
struct Transfer {
  BlockCsr<B, kModes> P;              // smoothed prolongator, pattern of A T
  std::vector<int> tentative_block;   // per node: the block (i, aggregate of i) of P
  std::vector<int> smoothing_target;  // per block k of A: the block of P that A_k T lands in
  // R = P^T by rows of the next level: its entries e are blocks restriction_source[e] of P
  // (the restriction and the Galerkin product, by the owner of each coarse row).
  BlockCsr<kModes, B> R;
  std::vector<int> restriction_source;
  double omega = 0.0;  // prolongator smoothing weight 4 / (3 rho)
};

// The symbolic tables of A_c = P^T (A P) and the numbers of A P in between.
template <int B>
struct GalerkinTables {
  // P's blocks transposed, per block m of P (A P is formed as (A P)^T = P^T A, on 6-row columns).
  std::vector<Eigen::Matrix<double, kModes, B>> p_transposed;
  // A P on its pattern (its values transposed, in ap_transposed), every row: row i is computed
  // by the owner of fine row i; per product A_k P_m (row by row, in loop order), where it lands.
  BlockCsr<B, kModes> AP;
  std::vector<Eigen::Matrix<double, kModes, B>> ap_transposed;
  std::vector<int> ap_target;
  std::vector<int> ap_row_first;  // per row: its first product's index into ap_target
  // A_c is symmetric: only its blocks (c, d) with d >= c are computed, by the owner of row c.
  // Per block m of P (in row i, column c), the first block of row i of A P with a column >= c;
  // per coarse row c, its targets start at coarse_row_first[c], in loop order.
  std::vector<int> upper_first;
  std::vector<int> coarse_target, coarse_row_first;
};

// The smoother's numbers, recomputed by prepare.
template <int B>
struct SmootherNumbers {
  // Per node: (D_i + diag(l1_i))^-1 for Gauss-Seidel, D_i^-1 otherwise; l1_i the row sums of
  // |a| over the couplings to other row blocks.
  std::vector<Eigen::Matrix<double, B, B>> inverse_diagonal;
  std::vector<Eigen::Matrix<double, B, 1>> l1;
  bool gauss_seidel = false;
  int sweeps = 1;               // Gauss-Seidel: sweeps per smoothing
  std::vector<double> weights;  // polynomial smoothers: per step, the weights of d and D^-1 r
  double jacobi_weight = 0.0;   // Jacobi smoother
  double lambda_max = 0.0;      // rho(D^-1 A) (Chebyshev smoother)
  Eigen::VectorXd power_start;  // the last power iteration's vector
};

// A level's vectors in the V-cycle: right-hand side, solution, the ping-pong partner of x,
// residual, polynomial smoother's direction. Scalar: the V-cycle's arithmetic.
template <class Scalar>
struct WorkVectors {
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  Vector b, x, y, residual, direction;
  void resize(Eigen::Index size) {
    for (Vector* v : {&b, &x, &y, &residual, &direction}) v->setZero(size);
  }
};

// The coarsest level's dense matrix and its Cholesky factor (Eigen's LLT, in place).
struct CoarsestSolve {
  Eigen::MatrixXd dense;
  Eigen::LLT<Eigen::MatrixXd> cholesky;
};

// One level of the hierarchy; B is the block size of its unknowns (3 on the mesh, 6 on the
// aggregates). The finest level's matrix values belong to the caller.
template <int B>
struct Level {
  using Block = Eigen::Matrix<double, B, B>;
  static constexpr int block_size = B;

  BlockCsr<B, B> A;  // pattern; values in A.blocks except on the finest level
  const Block* values = nullptr;
  std::vector<int> diagonal;   // per node: index of block (i, i)
  std::vector<int> transpose;  // per block (i, j): index of block (j, i) (coarse levels)
  RowBlocks rows;
  SmootherNumbers<B> smoother;
  // Per node of a coarse level: 1 on the modes its aggregate lacks (constrained or
  // degenerate), where the Galerkin matrix is zero and gets the identity, as I - S does.
  std::vector<Eigen::Matrix<double, B, 1>> missing_modes;
  bool coarsest = true;  // no transfer below: solved by the dense Cholesky
  Transfer<B> transfer;
  GalerkinTables<B> galerkin;
  CoarsestSolve coarsest_solve;
  WorkVectors<double> vectors;

  int nodes() const { return A.block_rows(); }
  int dofs() const { return B * nodes(); }
};

// The level whose pattern, row blocks and transfers the V-cycle and the smoothers read: a
// level that stores other numbers on the same hierarchy answers with the level it copies.
template <int B>
const Level<B>& source_level(const Level<B>& level) {
  return level;
}

// The level's fixed row blocks, as chapter 09's RowChunks: equal numbers of stored blocks,
// their count a function of the level's size alone (a 6x6 row weighs about four 3x3 rows).
template <int B>
void partition(Level<B>& level, const RowBlockSettings& settings) {
  const auto& A = level.A;
  const int rows = level.nodes();
  const int min_rows = std::max(1, settings.block_rows * 9 / (B * B));
  const int count = std::clamp(rows / min_rows, 1, settings.max_blocks);
  RowBlocks& blocks = level.rows;
  blocks.part = ch09::equal_block_partition(A.row_start, count);
  blocks.inner_begin.resize(rows);
  blocks.inner_end.resize(rows);
  for (int p = 0; p < count; ++p)
    for (int i = blocks.part[p]; i < blocks.part[p + 1]; ++i) {
      const auto first = A.column.begin() + A.row_start[i],
                 last = A.column.begin() + A.row_start[i + 1];
      blocks.inner_begin[i] =
          static_cast<int>(std::lower_bound(first, last, blocks.part[p]) - A.column.begin());
      blocks.inner_end[i] =
          static_cast<int>(std::lower_bound(first, last, blocks.part[p + 1]) - A.column.begin());
    }
  blocks.serial = rows < settings.serial_rows;
}

// The level's diagonal and transpose tables, its row blocks and its vectors.
template <int B>
void set_up_level(Level<B>& level, const RowBlockSettings& settings) {
  const int n = level.nodes();
  level.diagonal.resize(n);
  for (int i = 0; i < n; ++i) level.diagonal[i] = level.A.find(i, i);
  level.transpose.resize(level.A.column.size());
  for (int i = 0; i < n; ++i)
    for (int k = level.A.row_start[i]; k < level.A.row_start[i + 1]; ++k)
      level.transpose[k] = level.A.find(level.A.column[k], i);
  partition(level, settings);
  level.smoother.inverse_diagonal.resize(n);
  level.smoother.l1.assign(n, Eigen::Matrix<double, B, 1>::Zero());
  level.vectors.resize(level.dofs());
}

// ---- the block kernels ----------------------------------------------------------------------

// acc += M x for a small fixed-size block, column by column: Eigen leaves its own 6x6 product
// out of line (a call per block, which the coarse level's products would pay on every block);
// this form inlines into a few vector multiply-adds.
template <int R, int C>
EIGEN_ALWAYS_INLINE void add_product(Eigen::Matrix<double, R, 1>& acc,
                                     const Eigen::Matrix<double, R, C>& M, const double* x) {
  for (int j = 0; j < C; ++j) acc += M.col(j) * x[j];
}

// out += L M^T for small fixed-size blocks, column by column: each column of out is a sum of
// L's columns, vectors of R = 6 rows in the Galerkin products (3-row columns vectorize poorly).
template <int R, int K, int C>
EIGEN_ALWAYS_INLINE void add_product_transposed(Eigen::Matrix<double, R, C>& out,
                                                const Eigen::Matrix<double, R, K>& L,
                                                const Eigen::Matrix<double, C, K>& M) {
  for (int c = 0; c < C; ++c) {
    Eigen::Matrix<double, R, 1> sum = out.col(c);
    for (int t = 0; t < K; ++t) sum += L.col(t) * M(c, t);
    out.col(c) = sum;
  }
}

// sum of A_k x_(column k) over the blocks [begin, end) of a row, in two independent sums: the
// products of a row then overlap instead of waiting on each other's additions.
template <int B>
EIGEN_ALWAYS_INLINE Eigen::Matrix<double, B, 1> row_product(const Level<B>& level,
                                                            const Eigen::VectorXd& x, int begin,
                                                            int end) {
  using Vector = Eigen::Matrix<double, B, 1>;
  Vector even = Vector::Zero(), odd = Vector::Zero();
  const int* column = level.A.column.data();
  int k = begin;
  for (; k + 1 < end; k += 2) {
    add_product(even, level.values[k], x.data() + B * column[k]);
    add_product(odd, level.values[k + 1], x.data() + B * column[k + 1]);
  }
  if (k < end) add_product(even, level.values[k], x.data() + B * column[k]);
  return even + odd;
}

// y = A x on a level, one block row at a time (set-up only: one thread).
template <int B>
void multiply(const Level<B>& level, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  const auto& A = level.A;
  for (int i = 0; i < level.nodes(); ++i)
    y.template segment<B>(B * i) = row_product(level, x, A.row_start[i], A.row_start[i + 1]);
}

// ---- the coarsest level -----------------------------------------------------------------------

// Storage for the dense matrix and its factor, reserved at set-up. The factor is computed
// once here, on the zero matrix (it fails, harmlessly): Eigen's LLT(Index) constructor
// reserves the factor but leaves its m_info unset (Eigen/src/Cholesky/LLT.h), so a copy or
// move of it would read an indeterminate value; compute() sets every member, and the later
// computes of the same size reuse the storage (no allocation).
template <int B>
void finish_coarsest(Level<B>& level) {
  level.coarsest = true;
  level.coarsest_solve.dense.setZero(level.dofs(), level.dofs());
  level.coarsest_solve.cholesky.compute(level.coarsest_solve.dense);
}

// The coarsest level's numbers: its matrix dense, and its Cholesky factor (one thread).
template <int B>
void factorize_coarsest(Level<B>& level) {
  const auto& A = level.A;
  Eigen::MatrixXd& dense = level.coarsest_solve.dense;
  for (int i = 0; i < level.nodes(); ++i)
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
      dense.template block<B, B>(B * i, B * A.column[k]) = level.values[k];
  level.coarsest_solve.cholesky.compute(dense);  // same size as reserved: no allocation
}

// x = A^-1 x by the factor; a failed factor (an overflowed system) says so through the
// residual, as the other chapters do.
inline void solve_in_place(const CoarsestSolve& solve, Eigen::VectorXd& x) {
  if (solve.cholesky.info() == Eigen::Success)
    solve.cholesky.solveInPlace(x);
  else
    x.setConstant(std::numeric_limits<double>::quiet_NaN());
}

// The V-cycle's coarsest step: out = A^-1 b.
template <int B>
void solve_coarsest(Level<B>& level, const Eigen::VectorXd& b, Eigen::VectorXd& out) {
  out = b;
  solve_in_place(level.coarsest_solve, out);
}

}  // namespace fem::ch10
