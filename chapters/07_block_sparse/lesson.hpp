// The measurement behind chapter 07's lesson table: `fem_lessons spmv`, SpMV by Eigen (both storage
// orders) and by 3x3 blocks (full and symmetric storage), and block Jacobi against scalar Jacobi in
// the PCG.
#pragma once

#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "common/lesson.hpp"

namespace fem::ch07 {

std::vector<Lesson> lessons();

// The alternative the lesson measures, symmetric storage: only the blocks with j >= i
// (upper), and y = A x from them (multiply_upper: y_i += A_ij x_j and y_j += A_ij^T x_i, half
// the blocks read, but y is scattered).
BlockSparseMatrix upper(const BlockSparseMatrix& A);
void multiply_upper(const BlockSparseMatrix& upper, const Eigen::VectorXd& x, Eigen::VectorXd& y);

}  // namespace fem::ch07
