// Chapter 04: system composition in one pass. M, df/dv and df/dx share one sparsity
// pattern (the mesh connectivity), so A = M - h df/dv - h^2 df/dx is a loop over value
// arrays into a matrix allocated once, not a sparse expression that builds a new matrix.
#pragma once

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>
#include <array>
#include <vector>

#include "common/model.hpp"
#include "common/stepper.hpp"

namespace fem::ch04 {

class SystemCompositionStepper final : public Stepper {
 public:
  SystemCompositionStepper(const Scene& scene, const SolverSettings& settings);
  void step(State& state) override;
  const StepProfile& profile() const override { return profile_; }

  // The last step's filtered system S A S^T + I - S and right-hand side S (b - A z):
  // the reference that later chapters' in-place constraints are checked against.
  const Eigen::SparseMatrix<double>& system_matrix() const { return filtered_A_; }
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
  Eigen::SparseMatrix<double> S_;           // the constraint filter, 3x3 blocks S_i on the diagonal
  Eigen::VectorXd z_;                       // prescribed velocity change of constrained dofs
  Eigen::SparseMatrix<double> filtered_A_;  // S A S^T + I - S
  Eigen::VectorXd filtered_b_;              // S (b - A z)
  Eigen::VectorXd dv_;

  // Reused across steps: sized on the first step, never reallocated afterwards.
  Eigen::VectorXd scaled_v_;        // (h + beta) v, the vector df/dx multiplies in b
  Eigen::VectorXd unfiltered_rhs_;  // b - A z, before the product with S
  std::vector<Eigen::Triplet<double>> s_triplets_;
  std::vector<bool> constrained_;
  Eigen::SparseMatrix<double> identity_;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>> cg_;  // default: Lower, Jacobi
};

}  // namespace fem::ch04
