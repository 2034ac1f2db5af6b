// Chapter 10: what a hierarchy holds, level by level, for the tests and the lesson (these
// allocate: not for a step). Level 0 is the mesh; the prolongator of level l maps level l + 1
// onto level l.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "chapters/10_multigrid/multigrid.hpp"

namespace fem::ch10 {

int level_dofs(const Multigrid& mg, int level);
long long level_blocks(const Multigrid& mg, int level);        // stored blocks of its matrix
long long prolongator_blocks(const Multigrid& mg, int level);  // blocks of its P
int level_row_blocks(const Multigrid& mg, int level);          // its fixed row blocks
Eigen::SparseMatrix<double> level_matrix(const Multigrid& mg, int level);
Eigen::SparseMatrix<double> prolongator(const Multigrid& mg, int level);
// The identity diagonal added on the modes that the aggregates of level (>= 1) lack.
Eigen::VectorXd missing_modes(const Multigrid& mg, int level);

}  // namespace fem::ch10
