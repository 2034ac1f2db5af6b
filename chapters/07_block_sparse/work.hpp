// This chapter's work per phase (chapters/work.hpp: the model), and the counts of its data
// model for the chapters that keep it: matrices of 3x3 blocks in block compressed rows, the
// constraints on the blocks of constrained rows and columns, block Jacobi.
#pragma once

#include <vector>

#include "chapters/01_naive/work.hpp"
#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/07_block_sparse/stepper.hpp"
#include "chapters/work.hpp"

namespace fem::ch07 {

std::vector<PhaseWork> count_work(const BlockSparseStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts);

// Blocks and indices of block compressed rows, at `scalar` bytes per number.
template <int R, int C>
double matrix_bytes(const BlockCsr<R, C>& m, int scalar = 8) {
  return double(m.blocks.size()) * R * C * scalar +
         double(m.column.size() + m.row_start.size()) * sizeof(int);
}

// Block Jacobi: the inverse diagonal blocks read, one 3x3 product per node.
PhaseWork block_jacobi(const ch01::MeshSizes& m);

// The constraints on 3x3 blocks, in place: the blocks of the constrained nodes' rows and
// columns read and written back, b read, S (b - A z) written.
PhaseWork block_constraints(const ch01::MeshSizes& m, const BlockSparseMatrix& A,
                            const Scene& scene);

}  // namespace fem::ch07
