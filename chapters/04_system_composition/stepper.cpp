// Chapter 04: one linearized backward Euler step (Baraff & Witkin 1998),
//   A dv = b,  A = M - h df/dv - h^2 df/dx,  b = h (f + f_ext + df/dv v + h df/dx v),
// with velocity constraints by the filter S of the PPCG method (Tamstorf et al. 2015):
//   (S A S^T + I - S) y = S (b - A z),  dv = y + z.
// Chapter 04 changes only how A is composed: one pass over the value arrays.
#include "chapters/04_system_composition/stepper.hpp"

#include <algorithm>
#include <cassert>
#include <stdexcept>

namespace fem::ch04 {

using SparseMatrix = Eigen::SparseMatrix<double>;
using Triplet = Eigen::Triplet<double>;

SystemCompositionStepper::SystemCompositionStepper(const Scene& scene,
                                                   const SolverSettings& settings)
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
  dfdx_.setFromTriplets(pattern.begin(), pattern.end());  // compressed, sorted columns
  build_block_offsets();

  // A gets the pattern of df/dx once; M is diagonal, and the mesh pattern holds every
  // diagonal entry, so the lumped mass needs only the offsets of the diagonal.
  A_ = dfdx_;
  diagonal_offsets_.resize(n);
  for (int k = 0; k < n; ++k) {
    const int* first = std::lower_bound(dfdx_.innerIndexPtr() + dfdx_.outerIndexPtr()[k],
                                        dfdx_.innerIndexPtr() + dfdx_.outerIndexPtr()[k + 1], k);
    diagonal_offsets_[k] = static_cast<int>(first - dfdx_.innerIndexPtr());
  }

  S_.resize(n, n);
  identity_.resize(n, n);
  identity_.setIdentity();
  constrained_.assign(model_.num_nodes, false);
}

void SystemCompositionStepper::step(State& state) {
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

void SystemCompositionStepper::build_block_offsets() {
  // The binary searches that coeffRef did 144 times per element every step, done once.
  const int* outer = dfdx_.outerIndexPtr();
  const int* inner = dfdx_.innerIndexPtr();
  block_offsets_.resize(model_.tets.size());
  for (std::size_t e = 0; e < model_.tets.size(); ++e) {
    const Eigen::Vector4i& t = model_.tets[e];
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        for (int c = 0; c < 3; ++c) {
          const int col = 3 * t[b] + c;
          const int* first = std::lower_bound(inner + outer[col], inner + outer[col + 1], 3 * t[a]);
          block_offsets_[e][4 * a + b][c] = static_cast<int>(first - inner);
        }
      }
    }
  }
  if (!block_offsets_match_pattern())
    throw std::logic_error(
        "04_system_composition: the block offset table does not match the pattern");
}

bool SystemCompositionStepper::block_offsets_match_pattern() const {
  // The table is only valid for the compressed matrix it was built from: an insertion,
  // prune() or setZero() on dfdx_ would silently move entries under it.
  if (!dfdx_.isCompressed()) return false;
  const int* outer = dfdx_.outerIndexPtr();
  const int* inner = dfdx_.innerIndexPtr();
  for (std::size_t e = 0; e < model_.tets.size(); ++e) {
    const Eigen::Vector4i& t = model_.tets[e];
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int c = 0; c < 3; ++c) {
          const int offset = block_offsets_[e][4 * a + b][c];
          const int col = 3 * t[b] + c;
          if (offset < outer[col] || offset + 3 > outer[col + 1]) return false;
          for (int r = 0; r < 3; ++r)
            if (inner[offset + r] != 3 * t[a] + r) return false;
        }
  }
  return true;
}

void SystemCompositionStepper::build_dfdx() {
  assert(block_offsets_match_pattern());  // debug builds prove the invariant every step
  // Clean by zeroing the value array: the pattern (and so the table) stays valid.
  double* values = dfdx_.valuePtr();
  std::fill(values, values + dfdx_.nonZeros(), 0.0);
  for (std::size_t e = 0; e < model_.tets.size(); ++e) {
    const BlockOffsets& offsets = block_offsets_[e];
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        const Eigen::Matrix3d block = dfdx_block(model_.rest[e], rotations_[e], a, b);
        for (int c = 0; c < 3; ++c) {
          double* column = values + offsets[4 * a + b][c];
          for (int r = 0; r < 3; ++r) column[r] += block(r, c);
        }
      }
    }
  }
}

void SystemCompositionStepper::compose_system(const State& state) {
  const double h = scene_.dt;
  const double alpha = scene_.damping.alpha, beta = scene_.damping.beta;
  // A = M - h df/dv - h^2 df/dx = (1 + h alpha) M - (h beta + h^2) df/dx, entry by entry:
  // the sparse expression of chapter 03 allocated a new matrix, merged the patterns of M
  // and df/dx, and copied it into A_. Here one pass writes into the values of A_.
  const double stiffness_factor = -(h * beta + h * h);
  const double* dfdx = dfdx_.valuePtr();
  double* A = A_.valuePtr();
  const Eigen::Index nnz = dfdx_.nonZeros();
  for (Eigen::Index k = 0; k < nnz; ++k) A[k] = stiffness_factor * dfdx[k];
  const double mass_factor = 1.0 + h * alpha;
  for (int k = 0; k < model_.dofs; ++k)
    A[diagonal_offsets_[k]] += mass_factor * model_.lumped_mass[k];
  // b = h (f - alpha M v) + h df/dx ((h + beta) v), one product with a dense vector.
  scaled_v_ = (h + beta) * state.v;
  b_.noalias() = h * (dfdx_ * scaled_v_);
  b_ += h * f_ - (h * alpha) * model_.lumped_mass.cwiseProduct(state.v);
  b_ += h * f_ext_;  // a sparse vector added into a dense one: no temporary
}

void SystemCompositionStepper::apply_constraints(const State& state) {
  const int n = model_.dofs;
  // S is identity on free nodes and the filter S_i on constrained ones; z carries the
  // constrained part of the target velocity: z_i = (I - S_i)(v_target - v_i).
  // The triplet list and the flags keep their capacity from the previous step.
  std::fill(constrained_.begin(), constrained_.end(), false);
  s_triplets_.clear();
  z_.setZero(n);
  for (const auto& c : scene_.constraints) {
    constrained_[c.node] = true;
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k)
        if (c.filter(r, k) != 0.0)
          s_triplets_.emplace_back(3 * c.node + r, 3 * c.node + k, c.filter(r, k));
    z_.segment<3>(3 * c.node).noalias() = (Eigen::Matrix3d::Identity() - c.filter) *
                                          (c.target_velocity - state.v.segment<3>(3 * c.node));
  }
  for (int i = 0; i < model_.num_nodes; ++i)
    if (!constrained_[i])
      for (int r = 0; r < 3; ++r) s_triplets_.emplace_back(3 * i + r, 3 * i + r, 1.0);
  // Building S and the sparse products still allocate (chapter 05 removes S).
  S_.setFromTriplets(s_triplets_.begin(), s_triplets_.end());
  const SparseMatrix S_transpose = S_.transpose();  // S^T is row-major: store it to mix it
  filtered_A_ = S_ * A_ * S_transpose + (identity_ - S_);
  // S (b - A z) as written evaluates A z into a temporary, then b - A z into another,
  // before the product with S: a reused vector, and every product its own noalias().
  unfiltered_rhs_ = b_;
  unfiltered_rhs_.noalias() -= A_ * z_;
  filtered_b_.noalias() = S_ * unfiltered_rhs_;
}

void SystemCompositionStepper::solve() {
  cg_.setTolerance(settings_.tolerance);  // Eigen's default is machine epsilon
  cg_.setMaxIterations(settings_.max_iterations);
  cg_.compute(filtered_A_);
  // `cg_.solve(b) + z` would evaluate the solve into a temporary before the sum.
  dv_ = cg_.solve(filtered_b_);
  dv_ += z_;
  profile_.cg_iterations = static_cast<int>(cg_.iterations());
  profile_.relative_residual = cg_.error();
  profile_.converged = cg_.info() == Eigen::Success;
  report_if_not_converged(profile_, settings_, name().c_str(), warned_not_converged_);
}

}  // namespace fem::ch04
