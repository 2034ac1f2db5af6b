// Chapter 01: one linearized backward Euler step (Baraff & Witkin 1998),
//   A dv = b,  A = M - h df/dv - h^2 df/dx,  b = h (f + f_ext + df/dv v + h df/dx v),
// with velocity constraints by the filter S of the PPCG method (Tamstorf et al. 2015):
//   (S A S^T + I - S) y = S (b - A z),  dv = y + z.
// Written the way Eigen's documentation suggests, without thinking about memory.
#include "chapters/01_naive/stepper.hpp"

namespace fem::ch01 {

using SparseMatrix = Eigen::SparseMatrix<double>;
using Triplet = Eigen::Triplet<double>;

NaiveStepper::NaiveStepper(const Scene& scene, const SolverSettings& settings)
    : Stepper(scene), scene_(scene), model_(scene), settings_(settings) {
  const int n = model_.dofs;
  rotations_.resize(model_.tets.size());
  f_.resize(n);

  // The pattern of df/dx is the mesh connectivity: a 3x3 block per pair of nodes that
  // share a tetrahedron. Allocated once here; each step only overwrites the values.
  std::vector<Triplet> pattern;
  const auto adjacency = node_adjacency(scene.mesh);
  for (int i = 0; i < model_.num_nodes; ++i)
    for (const int j : adjacency[i])
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) pattern.emplace_back(3 * i + r, 3 * j + c, 0.0);
  dfdx_.resize(n, n);
  dfdx_.setFromTriplets(pattern.begin(), pattern.end());

  std::vector<Triplet> mass;
  for (int k = 0; k < n; ++k) mass.emplace_back(k, k, model_.lumped_mass[k]);
  M_.resize(n, n);
  M_.setFromTriplets(mass.begin(), mass.end());
}

void NaiveStepper::step(State& state) {
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

void NaiveStepper::build_dfdx() {
  dfdx_.coeffs().setZero();  // keeps the pattern (setZero() on the matrix would drop it)
  for (std::size_t e = 0; e < model_.tets.size(); ++e) {
    const Eigen::Vector4i& t = model_.tets[e];
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        const Eigen::Matrix3d block = dfdx_block(model_.rest[e], rotations_[e], a, b);
        // coeffRef finds each entry by a binary search in its column: 144 searches
        // per element, every step.
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) dfdx_.coeffRef(3 * t[a] + r, 3 * t[b] + c) += block(r, c);
      }
    }
  }
}

void NaiveStepper::compose_system(const State& state) {
  const double h = scene_.dt;
  const double alpha = scene_.damping.alpha, beta = scene_.damping.beta;
  // Rayleigh damping: df/dv = -(alpha M + beta K) with K = -df/dx.
  const SparseMatrix dfdv = -alpha * M_ + beta * dfdx_;
  A_ = M_ - h * dfdv - h * h * dfdx_;
  // f holds the elastic forces and gravity; the damping force is df/dv v.
  b_ = h * (f_ + dfdv * state.v + h * (dfdx_ * state.v));
  b_ += h * f_ext_;
}

void NaiveStepper::apply_constraints(const State& state) {
  const int n = model_.dofs;
  // S is identity on free nodes and the filter S_i on constrained ones; z carries the
  // constrained part of the target velocity: z_i = (I - S_i)(v_target - v_i).
  std::vector<bool> constrained(model_.num_nodes, false);
  std::vector<Triplet> s;
  z_ = Eigen::VectorXd::Zero(n);
  for (const auto& c : scene_.constraints) {
    constrained[c.node] = true;
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k)
        if (c.filter(r, k) != 0.0) s.emplace_back(3 * c.node + r, 3 * c.node + k, c.filter(r, k));
    z_.segment<3>(3 * c.node) = (Eigen::Matrix3d::Identity() - c.filter) *
                                (c.target_velocity - state.v.segment<3>(3 * c.node));
  }
  for (int i = 0; i < model_.num_nodes; ++i)
    if (!constrained[i])
      for (int r = 0; r < 3; ++r) s.emplace_back(3 * i + r, 3 * i + r, 1.0);
  S_.resize(n, n);
  S_.setFromTriplets(s.begin(), s.end());

  SparseMatrix identity(n, n);
  identity.setIdentity();
  const SparseMatrix S_transpose = S_.transpose();  // S^T is row-major: store it to mix it
  filtered_A_ = S_ * A_ * S_transpose + (identity - S_);
  filtered_b_ = S_ * (b_ - A_ * z_);
}

void NaiveStepper::solve() {
  cg_.setTolerance(settings_.tolerance);  // Eigen's default is machine epsilon
  cg_.setMaxIterations(settings_.max_iterations);
  cg_.compute(filtered_A_);
  dv_ = cg_.solve(filtered_b_) + z_;
  profile_.cg_iterations = static_cast<int>(cg_.iterations());
  profile_.relative_residual = cg_.error();
  profile_.converged = cg_.info() == Eigen::Success;
  report_if_not_converged(profile_, settings_, name().c_str(), warned_not_converged_);
}

}  // namespace fem::ch01
