// Chapter 07's building block: a sparse matrix of small dense blocks in block compressed
// rows, what Eigen's unsupported BlockSparseMatrix would have been. The stepper's matrices
// are 3x3 blocks (one per pair of nodes that share a tetrahedron); the block size is a
// parameter, so any R x C blocks (6x6, 3x6) are stored the same way.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <vector>

#include "common/scene.hpp"

namespace fem::ch07 {

// Block compressed rows with R x C blocks: row i holds blocks row_start[i] .. row_start[i+1]-1,
// block k is blocks[k] at block column column[k], columns sorted within a row.
template <int R, int C>
struct BlockCsr {
  using Block = Eigen::Matrix<double, R, C>;
  std::vector<int> row_start{0};
  std::vector<int> column;
  std::vector<Block> blocks;

  BlockCsr() = default;
  // The pattern of rows[i] (each sorted), with zero blocks.
  explicit BlockCsr(const std::vector<std::vector<int>>& rows) {
    for (const auto& row : rows) {
      column.insert(column.end(), row.begin(), row.end());
      row_start.push_back(static_cast<int>(column.size()));
    }
    blocks.assign(column.size(), Block::Zero());
  }

  int block_rows() const { return static_cast<int>(row_start.size()) - 1; }
  // Index of block (i, j) in blocks, found by a binary search: for set-up only. -1 if absent.
  int find(int i, int j) const;
  // y_i = sum_j A_ij x_j for the block rows [first, last): each y_i written once, from a sum
  // kept in registers, so that any split of the rows can run on threads of its own.
  void multiply_rows(const Eigen::VectorXd& x, Eigen::VectorXd& y, int first, int last) const {
    for (int i = first; i < last; ++i) {
      Eigen::Matrix<double, R, 1> sum = Eigen::Matrix<double, R, 1>::Zero();
      for (int k = row_start[i]; k < row_start[i + 1]; ++k)
        sum.noalias() += blocks[k] * x.template segment<C>(C * column[k]);
      y.template segment<R>(R * i) = sum;
    }
  }
  // y = A x.
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
    multiply_rows(x, y, 0, block_rows());
  }
  // Conversion for tests and comparisons (allocates); cols scalar columns.
  Eigen::SparseMatrix<double> to_sparse(int cols) const { return to_sparse(blocks.data(), cols); }
  Eigen::SparseMatrix<double> to_sparse() const { return to_sparse(C * block_rows()); }
  // The same with the values of another array on this pattern.
  Eigen::SparseMatrix<double> to_sparse(const Block* values, int cols) const;
};

// The stepper's matrix: 3x3 blocks, one block row per node.
using BlockSparseMatrix = BlockCsr<3, 3>;

// Where the stepper's terms land in the mesh's block pattern, found once by binary search so
// that no step searches.
struct BlockIndex {
  std::vector<std::array<int, 16>> element;  // per element: block of (a, b) at 4 a + b
  std::vector<int> diagonal;                 // per node: block (i, i)
  std::vector<int> transpose;                // per block (i, j): block (j, i)

  BlockIndex() = default;
  BlockIndex(const BlockSparseMatrix& pattern, const std::vector<Eigen::Vector4i>& tets);
};

// The constraints of chapter 05 on blocks, in place:
//   z_i = (I - S_i)(v_target - v_i),  filtered_b = S (b - A z),  A <- S A S^T + I - S.
// A row of blocks is contiguous and A is symmetric, so column i is found as the transposes'
// positions of row i (index.transpose).
void apply_constraints(const std::vector<NodeConstraint>& constraints, const Eigen::VectorXd& v,
                       const BlockIndex& index, const Eigen::VectorXd& b, BlockSparseMatrix& A,
                       Eigen::VectorXd& z, Eigen::VectorXd& filtered_b);

// ---- definitions of the templates -----------------------------------------------------

template <int R, int C>
int BlockCsr<R, C>::find(int i, int j) const {
  const auto first = column.begin() + row_start[i], last = column.begin() + row_start[i + 1];
  const auto it = std::lower_bound(first, last, j);
  return (it != last && *it == j) ? static_cast<int>(it - column.begin()) : -1;
}

template <int R, int C>
Eigen::SparseMatrix<double> BlockCsr<R, C>::to_sparse(const Block* values, int cols) const {
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < block_rows(); ++i)
    for (int k = row_start[i]; k < row_start[i + 1]; ++k)
      for (int r = 0; r < R; ++r)
        for (int c = 0; c < C; ++c) t.emplace_back(R * i + r, C * column[k] + c, values[k](r, c));
  Eigen::SparseMatrix<double> m(R * block_rows(), cols);
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

}  // namespace fem::ch07
