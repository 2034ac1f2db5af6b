// Chapter 07: beyond the poster, a 3x3 block sparse matrix. The poster ends: "we could do
// even better with sparse block matrices of 3x3 blocks; however, Eigen::BlockSparseMatrix
// is currently unsupported" (in Eigen 3.4 it does not even compile). This chapter writes the
// missing piece: one column index per 3x3 block instead of one per entry, blocks contiguous
// in memory, block-row products, and a block-Jacobi preconditioner.
#pragma once

#include <Eigen/SparseCore>
#include <array>
#include <vector>

#include "common/model.hpp"
#include "common/stepper.hpp"

namespace fem::ch07 {

// Block compressed-row storage: row i (node i) holds blocks row_start[i] .. row_start[i+1]-1,
// block k is blocks[k] at block column column[k], columns sorted within a row.
struct BlockSparseMatrix {
  std::vector<int> row_start;
  std::vector<int> column;
  std::vector<Eigen::Matrix3d> blocks;

  BlockSparseMatrix() = default;
  // The pattern of a symmetric node adjacency (each row sorted, the node itself included).
  explicit BlockSparseMatrix(const std::vector<std::vector<int>>& adjacency);

  int block_rows() const { return static_cast<int>(row_start.size()) - 1; }
  // Index of block (i, j) in blocks, found by a binary search: for set-up only.
  int find(int i, int j) const;
  // y = A x, one row of blocks at a time: y_i = sum_j A_ij x_j, each y_i written once.
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  // y = A x reading only the blocks with j >= i (A must be symmetric): y_i += A_ij x_j and
  // y_j += A_ij^T x_i. Half the blocks read, but y is scattered.
  void multiply_upper(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  // The same matrix with only the blocks j >= i: symmetric storage.
  BlockSparseMatrix upper() const;
  // Conversion for tests and comparisons (allocates).
  Eigen::SparseMatrix<double> to_sparse() const;
};

// The work vectors of the PCG, sized on the first solve and reused afterwards.
struct PcgWorkspace {
  Eigen::VectorXd residual, preconditioned, direction, product;
  std::vector<Eigen::Matrix3d> inverse_diagonal;  // block Jacobi: (A_ii)^-1
};

struct PcgResult {
  int iterations = 0;
  // ||r|| / ||b|| with r the recurrence residual (r -= step q), filtered, as Eigen's error():
  // it equals ||S (b - A y)|| / ||b|| only up to the rounding the recurrence accumulates.
  double relative_residual = 0.0;
  bool converged = false;
};

// Block-Jacobi preconditioned CG on the filtered block system, with the same stopping rule
// and PPCG filter as chapter 06. y holds the initial guess on entry and the solution on exit.
PcgResult pcg_solve(const BlockSparseMatrix& A, const std::vector<int>& diagonal_block,
                    const Eigen::VectorXd& b, const std::vector<NodeConstraint>& constraints,
                    const SolverSettings& settings, PcgWorkspace& work, Eigen::VectorXd& y);

class BlockSparseStepper final : public Stepper {
 public:
  BlockSparseStepper(const Scene& scene, const SolverSettings& settings);
  void step(State& state) override;
  const StepProfile& profile() const override { return profile_; }

  // The last step's filtered system S A S^T + I - S and right-hand side S (b - A z).
  const BlockSparseMatrix& system_matrix() const { return A_; }
  const Eigen::VectorXd& system_rhs() const { return filtered_b_; }
  const BlockSparseMatrix& dfdx() const { return dfdx_; }
  const std::vector<int>& diagonal_blocks() const { return diagonal_block_; }

 private:
  void build_dfdx();
  void compose_system(const State& state);
  void apply_constraints(const State& state);
  void solve();

  Scene scene_;
  Model model_;
  SolverSettings settings_;
  StepProfile profile_;
  bool warned_not_converged_ = false;

  std::vector<Eigen::Matrix3d> rotations_;           // R_e of the polar decomposition, per element
  Eigen::VectorXd f_;                                // elastic forces + gravity
  BlockSparseMatrix dfdx_;                           // pattern of the mesh connectivity, built once
  std::vector<std::array<int, 16>> element_blocks_;  // per element: block of (a, b)
  BlockSparseMatrix A_;               // M - h df/dv - h^2 df/dx, the pattern of dfdx_
  std::vector<int> diagonal_block_;   // per node: index of block (i, i)
  std::vector<int> transpose_block_;  // per block (i, j): index of block (j, i)
  Eigen::VectorXd b_;                 // h (f + f_ext + df/dv v + h df/dx v)
  Eigen::VectorXd z_;                 // prescribed velocity change of constrained dofs
  Eigen::VectorXd filtered_b_;        // S (b - A z)
  Eigen::VectorXd dv_;
  Eigen::VectorXd scaled_v_;  // (h + beta) v, the vector df/dx multiplies in b
  PcgWorkspace pcg_;
  Eigen::VectorXd y_;  // the unknown of the filtered system, dv = y + z: also the warm start
};

}  // namespace fem::ch07
