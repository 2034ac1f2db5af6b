// Chapter 08: the element loop at the speed of its arithmetic. Until now every chapter
// called common/'s element kernels: a JacobiSVD per element for the rotation, a stored
// 12x12 K0 per element (1.3 KB of rest data), df/dx built and then composed into A. This
// chapter makes the element work its own: the rotation by a Newton iteration warm-started
// from the last steps' rotations, the blocks of -df/dx in closed form from the shape gradients,
// and one pass over the elements that writes forces and blocks straight into b and A.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "chapters/07_block_sparse/block_pcg.hpp"
#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/08_element_kernels/element_kernels.hpp"
#include "common/model.hpp"
#include "common/stepper.hpp"

namespace fem::ch08 {

using ch07::BlockIndex;
using ch07::BlockSparseMatrix;

// The three marked phases are virtual: a derived stepper may replace them and keep the rest
// of the step.
class ElementKernelsStepper : public Stepper {
 public:
  ElementKernelsStepper(const Scene& scene, const SolverSettings& settings);
  void step(State& state) override;
  // forces: the fused element pass (rotations, element forces, and the blocks of df/dx
  // written into A and b); dfdx: zero, no df/dx is built; compose: what is left of the
  // composition, A = (1 + h alpha) M and the mass, gravity and interaction terms of b.
  const StepProfile& profile() const override { return profile_; }

  // The last step's filtered system S A S^T + I - S and right-hand side S (b - A z).
  const BlockSparseMatrix& system_matrix() const { return A_; }
  const Eigen::VectorXd& system_rhs() const { return filtered_b_; }
  const std::vector<int>& diagonal_blocks() const { return index_.diagonal; }
  // The element loop's shapes, rotations and fallback counts.
  const FusedElements& elements() const { return elements_; }

 protected:
  // What the elements do not touch: A = (1 + h alpha) M, b = h (f_gravity - alpha M v + f_ext).
  virtual void start_system(const State& state);
  // The fused pass: rotations, forces and the blocks of df/dx, written into A and b.
  virtual void element_pass(const State& state);
  // y = the filtered system's solution (warm-started from the last one), dv = y + z.
  virtual void solve();

  Scene scene_;
  Model model_;
  SolverSettings settings_;
  StepProfile profile_;
  bool warned_not_converged_ = false;

  FusedElements elements_;

  // The system A dv = b a step builds, for a later chapter's start_system or element_pass
  // to write: the one way in, so that `grep system_to_write` finds every place that writes it.
  BlockSparseMatrix& system_to_write() { return A_; }
  Eigen::VectorXd& rhs_to_write() { return b_; }

 private:
  BlockSparseMatrix A_;  // M - h df/dv - h^2 df/dx, the mesh's block pattern

 protected:
  BlockIndex index_;  // where element, diagonal and transposed blocks sit in A_

 private:
  Eigen::VectorXd b_;  // h (f + h df/dx v)

 protected:
  Eigen::VectorXd z_;           // prescribed velocity change of constrained dofs
  Eigen::VectorXd filtered_b_;  // S (b - A z)
  Eigen::VectorXd dv_;
  ch07::PcgWorkspace pcg_;
  Eigen::VectorXd y_;  // the unknown of the filtered system, dv = y + z: also the warm start
};

}  // namespace fem::ch08
