// Chapter 08's parts (see serial_parts.hpp), and the system a step builds (step.hpp).
#include "chapters/08_element_kernels/serial_parts.hpp"

#include <Eigen/LU>
#include <cassert>

namespace fem::ch08 {

System::System(const Scene& scene, const Model& model)
    // The pattern, once: a block per pair of nodes that share a tetrahedron. Where each
    // element's 16 blocks sit, the diagonal blocks and the transposes are found once too.
    : A(node_adjacency(scene.mesh)), index(A, model.tets) {
  b.resize(model.dofs);
  y.setZero(model.dofs);
}

SerialElements::SerialElements(const PartSetup& setup, const Params&)
    : elements_(setup.model, setup.scene) {}

void SerialElements::start_system(const StepInput& in, const State& state, System& system) const {
  const double h = in.scene.dt, alpha = in.scene.damping.alpha;
  for (auto& block : system.A.blocks) block.setZero();
  const double mass_factor = 1.0 + h * alpha;
  for (int i = 0; i < in.model.num_nodes; ++i)
    system.A.blocks[system.index.diagonal[i]].diagonal() =
        mass_factor * in.model.lumped_mass.segment<3>(3 * i);
  system.b.noalias() =
      h * in.model.gravity_force - (h * alpha) * in.model.lumped_mass.cwiseProduct(state.v);
  system.b += h * in.f_ext;  // a sparse vector added into a dense one: no temporary
}

void SerialElements::pass(const StepInput& in, const State& state, System& system) {
  long long fallbacks = 0;
  ElementTerms terms;
  const auto& tets = in.model.tets;
  for (int e = 0; e < static_cast<int>(tets.size()); ++e) {
    elements_.terms(e, tets[e], state, fallbacks, terms);
    scatter(tets[e], system.index.element[e], terms, system.A, system.b);
  }
  elements_.end_pass(fallbacks);
}

void PreconditionerPart::apply_rows(int, int, const Eigen::VectorXd&, Eigen::VectorXd&) const {
  assert(false && "apply_rows: only a block-diagonal preconditioner applies rows alone");
}

void PreconditionerPart::set_constraints(const std::vector<NodeConstraint>&) {}

BlockJacobi::BlockJacobi(const PartSetup& setup, const Params&)
    : diagonal_block_(setup.system.index.diagonal), inverse_diagonal_(diagonal_block_.size()) {}

void BlockJacobi::invert_rows(const BlockSparseMatrix& A, int first, int last) {
  for (int i = first; i < last; ++i) inverse_diagonal_[i] = A.blocks[diagonal_block_[i]].inverse();
}

void BlockJacobi::prepare(const BlockSparseMatrix& A) {
#pragma omp single
  invert_rows(A, 0, static_cast<int>(diagonal_block_.size()));
}

void BlockJacobi::apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) {
  apply_rows(0, static_cast<int>(diagonal_block_.size()), r, s);
}

void BlockJacobi::apply_rows(int first, int last, const Eigen::VectorXd& r,
                             Eigen::VectorXd& s) const {
  for (int i = first; i < last; ++i)
    s.segment<3>(3 * i).noalias() = inverse_diagonal_[i] * r.segment<3>(3 * i);
}

}  // namespace fem::ch08
