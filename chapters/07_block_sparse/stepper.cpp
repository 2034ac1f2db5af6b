// Chapter 07: one linearized backward Euler step (Baraff & Witkin 1998),
//   A dv = b,  A = M - h df/dv - h^2 df/dx,  b = h (f + f_ext + df/dv v + h df/dx v),
// with velocity constraints by the filter S of the PPCG method (Tamstorf et al. 2015):
//   (S A S^T + I - S) y = S (b - A z),  dv = y + z.
// Chapter 07 changes the storage: 3x3 blocks in block compressed rows, instead of scalars
// in Eigen's compressed columns. Every phase is the one of chapter 06, written on blocks.
#include "chapters/07_block_sparse/stepper.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

namespace fem::ch07 {

// ---- the block sparse matrix ------------------------------------------------------

BlockSparseMatrix::BlockSparseMatrix(const std::vector<std::vector<int>>& adjacency) {
  row_start.assign(1, 0);
  for (const auto& row : adjacency) {
    column.insert(column.end(), row.begin(), row.end());
    row_start.push_back(static_cast<int>(column.size()));
  }
  blocks.assign(column.size(), Eigen::Matrix3d::Zero());
}

int BlockSparseMatrix::find(int i, int j) const {
  const auto first = column.begin() + row_start[i], last = column.begin() + row_start[i + 1];
  const auto it = std::lower_bound(first, last, j);
  return (it != last && *it == j) ? static_cast<int>(it - column.begin()) : -1;
}

void BlockSparseMatrix::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  const int n = block_rows();
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();  // in registers: y_i is written once
    for (int k = row_start[i]; k < row_start[i + 1]; ++k)
      sum.noalias() += blocks[k] * x.segment<3>(3 * column[k]);
    y.segment<3>(3 * i) = sum;
  }
}

void BlockSparseMatrix::multiply_upper(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  y.setZero();
  const int n = block_rows();
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    const Eigen::Vector3d xi = x.segment<3>(3 * i);
    for (int k = row_start[i]; k < row_start[i + 1]; ++k) {
      const int j = column[k];
      if (j < i) continue;  // only the upper blocks are read
      sum.noalias() += blocks[k] * x.segment<3>(3 * j);
      if (j != i) y.segment<3>(3 * j).noalias() += blocks[k].transpose() * xi;
    }
    y.segment<3>(3 * i) += sum;
  }
}

BlockSparseMatrix BlockSparseMatrix::upper() const {
  BlockSparseMatrix u;
  u.row_start.assign(1, 0);
  for (int i = 0; i < block_rows(); ++i) {
    for (int k = row_start[i]; k < row_start[i + 1]; ++k) {
      if (column[k] < i) continue;
      u.column.push_back(column[k]);
      u.blocks.push_back(blocks[k]);
    }
    u.row_start.push_back(static_cast<int>(u.column.size()));
  }
  return u;
}

Eigen::SparseMatrix<double> BlockSparseMatrix::to_sparse() const {
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < block_rows(); ++i)
    for (int k = row_start[i]; k < row_start[i + 1]; ++k)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) t.emplace_back(3 * i + r, 3 * column[k] + c, blocks[k](r, c));
  Eigen::SparseMatrix<double> m(3 * block_rows(), 3 * block_rows());
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

// ---- the stepper ------------------------------------------------------------------------

BlockSparseStepper::BlockSparseStepper(const Scene& scene, const SolverSettings& settings)
    : Stepper(scene), scene_(scene), model_(scene), settings_(settings) {
  const int n = model_.dofs;
  rotations_.resize(model_.tets.size());
  f_.resize(n);

  // The pattern, once: a block per pair of nodes that share a tetrahedron. Where each
  // element's 16 blocks sit, the diagonal blocks and the transposes are found once too.
  dfdx_ = BlockSparseMatrix(node_adjacency(scene.mesh));
  A_ = dfdx_;
  element_blocks_.resize(model_.tets.size());
  for (std::size_t e = 0; e < model_.tets.size(); ++e)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        element_blocks_[e][4 * a + b] = dfdx_.find(model_.tets[e][a], model_.tets[e][b]);
  diagonal_block_.resize(model_.num_nodes);
  for (int i = 0; i < model_.num_nodes; ++i) diagonal_block_[i] = dfdx_.find(i, i);
  transpose_block_.resize(dfdx_.blocks.size());
  for (int i = 0; i < model_.num_nodes; ++i)
    for (int k = dfdx_.row_start[i]; k < dfdx_.row_start[i + 1]; ++k)
      transpose_block_[k] = dfdx_.find(dfdx_.column[k], i);
  y_.setZero(n);
}

void BlockSparseStepper::step(State& state) {
  PhaseTimer total(profile_.step);
  {
    PhaseTimer t(profile_.forces);
    compute_rotations_and_forces(model_, state.x, rotations_, f_);
  }
  {
    PhaseTimer t(profile_.dfdx);
    build_dfdx();
  }
  {
    PhaseTimer t(profile_.compose);
    compose_system(state);
  }
  {
    PhaseTimer t(profile_.constraints);
    apply_constraints(state);
  }
  {
    PhaseTimer t(profile_.solve);
    solve();
  }
  state.v += dv_;
  state.x += scene_.dt * state.v;
}

void BlockSparseStepper::build_dfdx() {
  for (auto& block : dfdx_.blocks) block.setZero();
  for (std::size_t e = 0; e < model_.tets.size(); ++e)
    for (int ab = 0; ab < 16; ++ab)
      dfdx_.blocks[element_blocks_[e][ab]] +=
          dfdx_block(model_.rest[e], rotations_[e], ab / 4, ab % 4);
}

void BlockSparseStepper::compose_system(const State& state) {
  const double h = scene_.dt;
  const double alpha = scene_.damping.alpha, beta = scene_.damping.beta;
  // A = (1 + h alpha) M - (h beta + h^2) df/dx, block by block.
  const double stiffness_factor = -(h * beta + h * h);
  for (std::size_t k = 0; k < A_.blocks.size(); ++k)
    A_.blocks[k] = stiffness_factor * dfdx_.blocks[k];
  const double mass_factor = 1.0 + h * alpha;
  for (int i = 0; i < model_.num_nodes; ++i)
    A_.blocks[diagonal_block_[i]].diagonal() += mass_factor * model_.lumped_mass.segment<3>(3 * i);
  // b = h (f - alpha M v) + h df/dx ((h + beta) v), one block product with a dense vector.
  scaled_v_ = (h + beta) * state.v;
  b_.resize(model_.dofs);
  dfdx_.multiply(scaled_v_, b_);
  b_ *= h;
  b_ += h * f_ - (h * alpha) * model_.lumped_mass.cwiseProduct(state.v);
  b_ += h * f_ext_;  // a sparse vector added into a dense one: no temporary
}

void BlockSparseStepper::apply_constraints(const State& state) {
  // z_i = (I - S_i)(v_target - v_i): the constrained part of the target velocity.
  z_.setZero(model_.dofs);
  for (const auto& c : scene_.constraints)
    z_.segment<3>(3 * c.node).noalias() = (Eigen::Matrix3d::Identity() - c.filter) *
                                          (c.target_velocity - state.v.segment<3>(3 * c.node));

  // S (b - A z): column i of A is row i transposed (A is symmetric), so the blocks a_ji
  // are the transposes of the blocks of row i, found through transpose_block_.
  filtered_b_ = b_;
  for (const auto& c : scene_.constraints) {
    const Eigen::Vector3d zi = z_.segment<3>(3 * c.node);
    if (zi.isZero(0.0)) continue;
    for (int k = A_.row_start[c.node]; k < A_.row_start[c.node + 1]; ++k)
      filtered_b_.segment<3>(3 * A_.column[k]).noalias() -= A_.blocks[transpose_block_[k]] * zi;
  }
  for (const auto& c : scene_.constraints)
    filtered_b_.segment<3>(3 * c.node) = c.filter * filtered_b_.segment<3>(3 * c.node);

  // S A S^T + I - S in place: a row of blocks is contiguous now, and the column blocks
  // a_ji are the transposes' positions of the row.
  for (const auto& c : scene_.constraints) {
    for (int k = A_.row_start[c.node]; k < A_.row_start[c.node + 1]; ++k) {
      A_.blocks[k] = c.filter * A_.blocks[k];
      Eigen::Matrix3d& a_ji = A_.blocks[transpose_block_[k]];
      a_ji = a_ji * c.filter;
    }
  }
  for (const auto& c : scene_.constraints)
    A_.blocks[diagonal_block_[c.node]] += Eigen::Matrix3d::Identity() - c.filter;
}

void BlockSparseStepper::solve() {
  // Warm start: y_ still holds the previous step's answer; pcg_solve filters it.
  const PcgResult result =
      pcg_solve(A_, diagonal_block_, filtered_b_, scene_.constraints, settings_, pcg_, y_);
  dv_ = y_;
  dv_ += z_;
  profile_.cg_iterations = result.iterations;
  profile_.relative_residual = result.relative_residual;
  profile_.converged = result.converged;
  report_if_not_converged(profile_, settings_, "07_block_sparse", warned_not_converged_);
}

// ---- the solver ---------------------------------------------------------------------------

namespace {

// v_i <- S_i v_i on the constrained nodes: the PPCG projection onto the free subspace.
void filter(const std::vector<NodeConstraint>& constraints, Eigen::VectorXd& v) {
  for (const auto& c : constraints) v.segment<3>(3 * c.node) = c.filter * v.segment<3>(3 * c.node);
}

// s_i = D_i^-1 r_i with D_i the 3x3 diagonal block: block Jacobi.
void precondition(const std::vector<Eigen::Matrix3d>& inverse_diagonal, const Eigen::VectorXd& r,
                  Eigen::VectorXd& s) {
  for (std::size_t i = 0; i < inverse_diagonal.size(); ++i)
    s.segment<3>(3 * i).noalias() = inverse_diagonal[i] * r.segment<3>(3 * i);
}

}  // namespace

PcgResult pcg_solve(const BlockSparseMatrix& A, const std::vector<int>& diagonal_block,
                    const Eigen::VectorXd& b, const std::vector<NodeConstraint>& constraints,
                    const SolverSettings& settings, PcgWorkspace& work, Eigen::VectorXd& y) {
  const Eigen::Index n = b.size();
  auto& [r, s, p, q, inverse_diagonal] = work;
  // Same sizes every step: these resizes allocate on the first solve only.
  r.resize(n);
  s.resize(n);
  p.resize(n);
  q.resize(n);
  inverse_diagonal.resize(diagonal_block.size());
  // The diagonal blocks of the filtered matrix are symmetric positive definite (a fixed
  // node's is the identity), so each has an inverse: a fixed-size 3x3 inverse, no search.
  for (std::size_t i = 0; i < diagonal_block.size(); ++i)
    inverse_diagonal[i] = A.blocks[diagonal_block[i]].inverse();

  PcgResult result;
  const double rhs_norm2 = b.squaredNorm();
  if (rhs_norm2 == 0.0) {  // as Eigen: the solution of A y = 0 is 0
    y.setZero();
    result.converged = true;
    return result;
  }
  filter(constraints, y);
  A.multiply(y, q);
  r = b - q;
  filter(constraints, r);
  const double threshold = std::max(settings.tolerance * settings.tolerance * rhs_norm2,
                                    std::numeric_limits<double>::min());
  double residual_norm2 = r.squaredNorm();
  if (residual_norm2 >= threshold) {
    precondition(inverse_diagonal, r, p);
    filter(constraints, p);
    double rho = r.dot(p);
    while (result.iterations < settings.max_iterations) {
      A.multiply(p, q);
      const double step = rho / p.dot(q);
      y += step * p;
      r -= step * q;
      filter(constraints, r);
      ++result.iterations;
      residual_norm2 = r.squaredNorm();
      if (residual_norm2 < threshold) break;
      precondition(inverse_diagonal, r, s);
      filter(constraints, s);
      const double rho_old = rho;
      rho = r.dot(s);
      p = s + (rho / rho_old) * p;
    }
  }
  result.relative_residual = std::sqrt(residual_norm2 / rhs_norm2);
  result.converged = residual_norm2 < threshold;
  return result;
}

}  // namespace fem::ch07
