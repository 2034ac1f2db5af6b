// Chapter 07: one linearized backward Euler step (Baraff & Witkin 1998),
//   A dv = b,  A = M - h df/dv - h^2 df/dx,  b = h (f + f_ext + df/dv v + h df/dx v),
// with velocity constraints by the filter S of the PPCG method (Tamstorf et al. 2015):
//   (S A S^T + I - S) y = S (b - A z),  dv = y + z.
// Chapter 07 changes the storage: 3x3 blocks in block compressed rows, instead of scalars
// in Eigen's compressed columns. Every phase is the one of chapter 06, written on blocks.
#include "chapters/07_block_sparse/stepper.hpp"

namespace fem::ch07 {

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
  index_ = BlockIndex(dfdx_, model_.tets);
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
    apply_constraints(scene_.constraints, state.v, index_, b_, A_, z_, filtered_b_);
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
      dfdx_.blocks[index_.element[e][ab]] +=
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
    A_.blocks[index_.diagonal[i]].diagonal() += mass_factor * model_.lumped_mass.segment<3>(3 * i);
  // b = h (f - alpha M v) + h df/dx ((h + beta) v), one block product with a dense vector.
  scaled_v_ = (h + beta) * state.v;
  b_.resize(model_.dofs);
  dfdx_.multiply(scaled_v_, b_);
  b_ *= h;
  b_ += h * f_ - (h * alpha) * model_.lumped_mass.cwiseProduct(state.v);
  b_ += h * f_ext_;  // a sparse vector added into a dense one: no temporary
}

void BlockSparseStepper::solve() {
  // Warm start: y_ still holds the previous step's answer; pcg_solve filters it.
  const SolveStats result =
      pcg_solve(A_, index_.diagonal, filtered_b_, scene_.constraints, settings_, pcg_, y_);
  dv_ = y_;
  dv_ += z_;
  profile_.record(result);
  report_if_not_converged(profile_, settings_, name().c_str(), warned_not_converged_);
}

}  // namespace fem::ch07
