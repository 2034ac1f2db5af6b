// Chapter 08: one linearized backward Euler step (Baraff & Witkin 1998),
//   A dv = b,  A = M - h df/dv - h^2 df/dx,  b = h (f + h df/dx v),
// with velocity constraints by the filter S of the PPCG method (Tamstorf et al. 2015):
//   (S A S^T + I - S) y = S (b - A z),  dv = y + z.
// Chapter 08 changes the element loop: rotations by a warm-started Newton iteration instead
// of an SVD, the blocks of df/dx in closed form instead of R K0 R^T with a stored K0, and
// one pass over the elements that writes into A and b directly, with no df/dx matrix.
#include "chapters/08_element_kernels/stepper.hpp"

namespace fem::ch08 {

ElementKernelsStepper::ElementKernelsStepper(const Scene& scene, const SolverSettings& settings)
    : Stepper(scene), scene_(scene), model_(scene), settings_(settings) {
  const int n = model_.dofs;
  elements_ = FusedElements(model_, scene);
  // The pattern, once: a block per pair of nodes that share a tetrahedron. Where each
  // element's 16 blocks sit, the diagonal blocks and the transposes are found once too.
  A_ = BlockSparseMatrix(node_adjacency(scene.mesh));
  index_ = BlockIndex(A_, model_.tets);
  b_.resize(n);
  y_.setZero(n);
}

void ElementKernelsStepper::step(State& state) {
  PhaseTimer total(profile_.step);
  {
    PhaseTimer t(profile_.compose);
    start_system(state);
  }
  {
    // The fused pass: rotations, forces and the blocks of df/dx, written into A and b. It
    // does the work of the earlier chapters' forces, df/dx and composition phases and is
    // reported under forces; dfdx stays zero, because no df/dx is built.
    PhaseTimer t(profile_.forces);
    element_pass(state);
  }
  profile_.dfdx = PhaseCost{};
  {
    PhaseTimer t(profile_.constraints);
    ch07::apply_constraints(scene_.constraints, state.v, index_, b_, A_, z_, filtered_b_);
  }
  {
    PhaseTimer t(profile_.solve);
    solve();
  }
  state.v += dv_;
  state.x += scene_.dt * state.v;
}

void ElementKernelsStepper::start_system(const State& state) {
  const double h = scene_.dt, alpha = scene_.damping.alpha;
  // What the elements do not touch: A = (1 + h alpha) M, b = h (f_gravity - alpha M v + f_ext).
  for (auto& block : A_.blocks) block.setZero();
  const double mass_factor = 1.0 + h * alpha;
  for (int i = 0; i < model_.num_nodes; ++i)
    A_.blocks[index_.diagonal[i]].diagonal() = mass_factor * model_.lumped_mass.segment<3>(3 * i);
  b_.noalias() = h * model_.gravity_force - (h * alpha) * model_.lumped_mass.cwiseProduct(state.v);
  b_ += h * f_ext_;  // a sparse vector added into a dense one: no temporary
}

void ElementKernelsStepper::element_pass(const State& state) {
  long long fallbacks = 0;
  ElementTerms terms;
  for (int e = 0; e < static_cast<int>(model_.tets.size()); ++e) {
    elements_.terms(e, model_.tets[e], state, fallbacks, terms);
    scatter(model_.tets[e], index_.element[e], terms, A_, b_);
  }
  elements_.end_pass(fallbacks);
}

void ElementKernelsStepper::solve() {
  // Warm start: y_ still holds the previous step's answer; pcg_solve filters it.
  const SolveStats result =
      ch07::pcg_solve(A_, index_.diagonal, filtered_b_, scene_.constraints, settings_, pcg_, y_);
  dv_ = y_;
  dv_ += z_;
  profile_.record(result);
  report_if_not_converged(profile_, settings_, "08_element_kernels", warned_not_converged_);
}

}  // namespace fem::ch08
