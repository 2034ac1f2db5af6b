// Chapter 07's solver: chapter 06's PCG on the block matrix, preconditioned by block Jacobi
// (the inverse of each node's 3x3 diagonal block).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "common/stepper.hpp"

namespace fem::ch07 {

// The work vectors of the PCG, sized on the first solve and reused afterwards.
struct PcgWorkspace {
  Eigen::VectorXd residual, preconditioned, direction, product;
  std::vector<Eigen::Matrix3d> inverse_diagonal;  // block Jacobi: (A_ii)^-1
};

// Block-Jacobi preconditioned CG on the filtered block system, with the same stopping rule
// and PPCG filter as chapter 06. y holds the initial guess on entry and the solution on exit.
SolveStats pcg_solve(const BlockSparseMatrix& A, const std::vector<int>& diagonal_block,
                     const Eigen::VectorXd& b, const std::vector<NodeConstraint>& constraints,
                     const SolverSettings& settings, PcgWorkspace& work, Eigen::VectorXd& y);

}  // namespace fem::ch07
