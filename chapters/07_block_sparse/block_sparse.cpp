// Chapter 07's block matrix: the tables that say where each term lands, and the
// constraints applied on blocks.
#include "chapters/07_block_sparse/block_sparse.hpp"

namespace fem::ch07 {

BlockIndex::BlockIndex(const BlockSparseMatrix& pattern, const std::vector<Eigen::Vector4i>& tets) {
  element.resize(tets.size());
  for (std::size_t e = 0; e < tets.size(); ++e)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) element[e][4 * a + b] = pattern.find(tets[e][a], tets[e][b]);
  const int nodes = pattern.block_rows();
  diagonal.resize(nodes);
  for (int i = 0; i < nodes; ++i) diagonal[i] = pattern.find(i, i);
  transpose.resize(pattern.column.size());
  for (int i = 0; i < nodes; ++i)
    for (int k = pattern.row_start[i]; k < pattern.row_start[i + 1]; ++k)
      transpose[k] = pattern.find(pattern.column[k], i);
}

void apply_constraints(const std::vector<NodeConstraint>& constraints, const Eigen::VectorXd& v,
                       const BlockIndex& index, const Eigen::VectorXd& b, BlockSparseMatrix& A,
                       Eigen::VectorXd& z, Eigen::VectorXd& filtered_b) {
  // z_i = (I - S_i)(v_target - v_i): the constrained part of the target velocity.
  z.setZero(v.size());
  for (const auto& c : constraints)
    z.segment<3>(3 * c.node).noalias() =
        (Eigen::Matrix3d::Identity() - c.filter) * (c.target_velocity - v.segment<3>(3 * c.node));

  // S (b - A z): column i of A is row i transposed (A is symmetric), so the blocks a_ji
  // are the transposes of the blocks of row i, found through index.transpose.
  filtered_b = b;
  for (const auto& c : constraints) {
    const Eigen::Vector3d zi = z.segment<3>(3 * c.node);
    if (zi.isZero(0.0)) continue;
    for (int k = A.row_start[c.node]; k < A.row_start[c.node + 1]; ++k)
      filtered_b.segment<3>(3 * A.column[k]).noalias() -= A.blocks[index.transpose[k]] * zi;
  }
  for (const auto& c : constraints)
    filtered_b.segment<3>(3 * c.node) = c.filter * filtered_b.segment<3>(3 * c.node);

  // S A S^T + I - S in place: a row of blocks is contiguous now, and the column blocks
  // a_ji are the transposes' positions of the row.
  for (const auto& c : constraints) {
    for (int k = A.row_start[c.node]; k < A.row_start[c.node + 1]; ++k) {
      A.blocks[k] = c.filter * A.blocks[k];
      Eigen::Matrix3d& a_ji = A.blocks[index.transpose[k]];
      a_ji = a_ji * c.filter;
    }
  }
  for (const auto& c : constraints)
    A.blocks[index.diagonal[c.node]] += Eigen::Matrix3d::Identity() - c.filter;
}

}  // namespace fem::ch07
