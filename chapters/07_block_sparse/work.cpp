#include "chapters/07_block_sparse/work.hpp"

namespace fem::ch07 {

namespace {

constexpr double kBlock = 9 * sizeof(double);  // a 3x3 block of doubles

// Blocks in the block rows of the constrained nodes.
double constrained_blocks(const BlockSparseMatrix& A, const Scene& scene) {
  double blocks = 0;
  for (const NodeConstraint& c : scene.constraints)
    blocks += A.row_start[c.node + 1] - A.row_start[c.node];
  return blocks;
}

}  // namespace

PhaseWork block_jacobi(const ch01::MeshSizes& m) {
  return ch01::phase_work("block jacobi", m.nodes * kBlock, 0.0, 0.0, m.nodes * ch01::kMatVec3Flops,
                          m.nodes * kBlock);
}

PhaseWork block_constraints(const ch01::MeshSizes& m, const BlockSparseMatrix& A,
                            const Scene& scene) {
  const double blocks = 2 * constrained_blocks(A, scene) * kBlock;  // rows and columns
  return ch01::phase_work("constraints", blocks + m.vector_bytes, blocks + m.vector_bytes,
                          m.vector_bytes, 2 * ch01::kMatMat3Flops * blocks / kBlock,
                          blocks + 2 * m.vector_bytes);
}

std::vector<PhaseWork> count_work(const BlockSparseStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts) {
  // common/'s element loop on df/dx and A of the same block pattern.
  const ch01::MeshSizes m = ch01::mesh_sizes(scene);
  const BlockSparseMatrix& A = stepper.system_matrix();
  const double matrix = matrix_bytes(A), entries = 9.0 * double(A.blocks.size());
  const double v = m.vector_bytes;
  const PhaseWork compose = ch01::phase_work("compose", matrix + 4 * v, matrix + v, matrix + v,
                                             4 * entries + 6 * m.dofs, 2 * matrix + 5 * v);
  return {ch01::reference_forces(m), ch01::reference_dfdx(m, matrix), compose,
          block_constraints(m, A, scene),
          ch01::pcg_work(m, counts.cg_iterations, matrix, 2 * entries, block_jacobi(m))};
}

}  // namespace fem::ch07
