// Chapter 06: our own preconditioned conjugate gradient. Eigen's CG is algorithmically
// as good as any, but it allocates its work vectors on every solve() and starts from zero.
// This one keeps its vectors, starts from the previous step's answer, reads its Jacobi
// preconditioner through the diagonal offsets, and filters inside the iteration (PPCG):
// the step performs no heap allocation at all.
#pragma once

#include <Eigen/SparseCore>
#include <array>
#include <vector>

#include "common/model.hpp"
#include "common/stepper.hpp"

namespace fem::ch06 {

// The work vectors of the PCG, sized on the first solve and reused afterwards.
struct PcgWorkspace {
  Eigen::VectorXd residual, preconditioned, direction, product, inverse_diagonal;
};

// Jacobi-preconditioned CG on the filtered system A y = b (A = S A S^T + I - S, b = S ...),
// with Eigen's stopping rule ||r|| <= tolerance ||b|| and an iteration cap. y holds the
// initial guess on entry (it is filtered first) and the solution on exit. The filter S_i
// of every constrained node is applied to the residual and the preconditioned residual
// in each iteration, so the iterates stay in the constrained subspace (Tamstorf et al.
// 2015). diagonal_offsets[k] is where entry (k, k) of A sits in A.valuePtr().
SolveStats pcg_solve(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b,
                     const std::vector<NodeConstraint>& constraints,
                     const std::vector<int>& diagonal_offsets, const SolverSettings& settings,
                     PcgWorkspace& work, Eigen::VectorXd& y);

// Where each diagonal entry sits in the value array of a compressed matrix.
std::vector<int> diagonal_offsets(const Eigen::SparseMatrix<double>& A);

class CustomPcgStepper final : public Stepper {
 public:
  CustomPcgStepper(const Scene& scene, const SolverSettings& settings);
  void step(State& state) override;
  const StepProfile& profile() const override { return profile_; }

  // The last step's filtered system S A S^T + I - S (A_, filtered in place) and
  // right-hand side S (b - A z).
  const Eigen::SparseMatrix<double>& system_matrix() const { return A_; }
  const Eigen::VectorXd& system_rhs() const { return filtered_b_; }
  const Eigen::SparseMatrix<double>& dfdx() const { return dfdx_; }

 private:
  // For element e and node pair (a, b): where column c of the 3x3 block (t[a], t[b])
  // starts in dfdx_.valuePtr(). Its three rows follow contiguously (compressed storage
  // keeps a column's entries sorted and contiguous, and the pattern has whole blocks).
  using BlockOffsets = std::array<std::array<int, 3>, 16>;
  void build_block_offsets();
  bool block_offsets_match_pattern() const;  // the debug check of the table's invariant
  void build_dfdx();
  void build_block_rows();
  // The 3x3 block of a matrix with the pattern of dfdx_: block k of column block j.
  Eigen::Map<Eigen::Matrix3d, 0, Eigen::OuterStride<>> block(Eigen::SparseMatrix<double>& m, int j,
                                                             int k) const;
  void compose_system(const State& state);
  void apply_constraints(const State& state);
  void solve();

  Scene scene_;
  Model model_;
  SolverSettings settings_;
  StepProfile profile_;
  bool warned_not_converged_ = false;

  std::vector<Eigen::Matrix3d> rotations_;   // R_e of the polar decomposition, per element
  Eigen::VectorXd f_;                        // elastic forces + gravity
  Eigen::SparseMatrix<double> dfdx_;         // pattern of the mesh connectivity, allocated once
  std::vector<BlockOffsets> block_offsets_;  // per element, built once with the pattern
  Eigen::SparseMatrix<double> A_;            // M - h df/dv - h^2 df/dx, the pattern of dfdx_
  std::vector<int> diagonal_offsets_;        // where entry (k, k) sits in the value arrays
  Eigen::VectorXd b_;                        // h (f + f_ext + df/dv v + h df/dx v)
  Eigen::VectorXd z_;                        // prescribed velocity change of constrained dofs
  Eigen::VectorXd filtered_b_;               // S (b - A z)
  Eigen::VectorXd dv_;

  // Reused across steps: sized on the first step, never reallocated afterwards.
  Eigen::VectorXd scaled_v_;  // (h + beta) v, the vector df/dx multiplies in b

  // The block structure of the pattern, built once. Column block j (the columns of node j)
  // holds one 3x3 block per neighbour i, in order; block k starts at row 3 * (its k-th
  // neighbour) of each of the three columns, column_stride_[j] = 3 * neighbours apart.
  std::vector<int> column_stride_;
  std::vector<int> diagonal_block_;  // k of the diagonal block (j, j) in column block j
  // Row blocks of node i, i.e. blocks (i, j): column block j and position k, CSR-like.
  std::vector<int> row_block_start_;
  std::vector<std::pair<int, int>> row_blocks_;
  PcgWorkspace pcg_;
  Eigen::VectorXd y_;  // the unknown of the filtered system, dv = y + z: also the warm start
};

}  // namespace fem::ch06
