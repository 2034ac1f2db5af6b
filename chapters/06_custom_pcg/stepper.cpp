// Chapter 06: one linearized backward Euler step (Baraff & Witkin 1998),
//   A dv = b,  A = M - h df/dv - h^2 df/dx,  b = h (f + f_ext + df/dv v + h df/dx v),
// with velocity constraints by the filter S of the PPCG method (Tamstorf et al. 2015):
//   (S A S^T + I - S) y = S (b - A z),  dv = y + z.
// Chapter 06 changes only the solve: our own PCG, warm-started, allocation-free.
#include "chapters/06_custom_pcg/stepper.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace fem::ch06 {

using SparseMatrix = Eigen::SparseMatrix<double>;
using Triplet = Eigen::Triplet<double>;

CustomPcgStepper::CustomPcgStepper(const Scene& scene, const SolverSettings& settings)
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
  diagonal_offsets_ = diagonal_offsets(A_);
  y_.setZero(n);

  build_block_rows();
}

void CustomPcgStepper::step(State& state) {
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

void CustomPcgStepper::build_block_offsets() {
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
    throw std::logic_error("06_custom_pcg: the block offset table does not match the pattern");
}

bool CustomPcgStepper::block_offsets_match_pattern() const {
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

void CustomPcgStepper::build_dfdx() {
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

void CustomPcgStepper::compose_system(const State& state) {
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

void CustomPcgStepper::build_block_rows() {
  const int nodes = model_.num_nodes;
  const int* outer = dfdx_.outerIndexPtr();
  const int* inner = dfdx_.innerIndexPtr();
  column_stride_.resize(nodes);
  diagonal_block_.resize(nodes);
  std::vector<std::vector<std::pair<int, int>>> rows(nodes);
  for (int j = 0; j < nodes; ++j) {
    column_stride_[j] = outer[3 * j + 1] - outer[3 * j];
    for (int k = 0; 3 * k < column_stride_[j]; ++k) {
      const int i = inner[outer[3 * j] + 3 * k] / 3;
      rows[i].emplace_back(j, k);
      if (i == j) diagonal_block_[j] = k;
    }
  }
  row_block_start_.assign(1, 0);
  for (const auto& r : rows) {
    row_blocks_.insert(row_blocks_.end(), r.begin(), r.end());
    row_block_start_.push_back(static_cast<int>(row_blocks_.size()));
  }
}

Eigen::Map<Eigen::Matrix3d, 0, Eigen::OuterStride<>> CustomPcgStepper::block(
    Eigen::SparseMatrix<double>& m, int j, int k) const {
  // The three columns of column block j are column_stride_[j] values apart, and block k
  // starts 3 k values into each: a 3x3 view with an outer stride, no copy.
  using BlockMap = Eigen::Map<Eigen::Matrix3d, 0, Eigen::OuterStride<>>;
  return BlockMap(m.valuePtr() + m.outerIndexPtr()[3 * j] + 3 * k,
                  Eigen::OuterStride<>(column_stride_[j]));
}

void CustomPcgStepper::apply_constraints(const State& state) {
  // z_i = (I - S_i)(v_target - v_i): the constrained part of the target velocity.
  z_.setZero(model_.dofs);
  for (const auto& c : scene_.constraints)
    z_.segment<3>(3 * c.node).noalias() = (Eigen::Matrix3d::Identity() - c.filter) *
                                          (c.target_velocity - state.v.segment<3>(3 * c.node));

  // S (b - A z), with A still unfiltered. z lives on constrained nodes only, so A z is
  // the sum of their column blocks times z_i; S is the identity but on those nodes.
  filtered_b_ = b_;
  for (const auto& c : scene_.constraints) {
    const Eigen::Vector3d zi = z_.segment<3>(3 * c.node);
    if (zi.isZero(0.0)) continue;
    const int* inner = A_.innerIndexPtr() + A_.outerIndexPtr()[3 * c.node];
    for (int k = 0; 3 * k < column_stride_[c.node]; ++k)
      filtered_b_.segment<3>(inner[3 * k]).noalias() -= block(A_, c.node, k) * zi;
  }
  for (const auto& c : scene_.constraints)
    filtered_b_.segment<3>(3 * c.node) = c.filter * filtered_b_.segment<3>(3 * c.node);

  // S A S^T + I - S in place: S_i from the left on the row blocks of a constrained node i,
  // S_i from the right on its column blocks. A block between two constrained nodes gets
  // both, S_i a_ij S_j; a block between free nodes is never touched.
  for (const auto& c : scene_.constraints) {
    const int i = c.node;
    for (int r = row_block_start_[i]; r < row_block_start_[i + 1]; ++r) {
      auto a_ij = block(A_, row_blocks_[r].first, row_blocks_[r].second);
      a_ij = c.filter * a_ij;  // a fixed-size 3x3 product: evaluated on the stack
    }
    for (int k = 0; 3 * k < column_stride_[i]; ++k) {
      auto a_ji = block(A_, i, k);
      a_ji = a_ji * c.filter;
    }
  }
  for (const auto& c : scene_.constraints)
    block(A_, c.node, diagonal_block_[c.node]) += Eigen::Matrix3d::Identity() - c.filter;
}

void CustomPcgStepper::solve() {
  // Warm start: y_ still holds the previous step's answer; pcg_solve filters it.
  const SolveStats result =
      pcg_solve(A_, filtered_b_, scene_.constraints, diagonal_offsets_, settings_, pcg_, y_);
  dv_ = y_;
  dv_ += z_;
  profile_.record(result);
  report_if_not_converged(profile_, settings_, name().c_str(), warned_not_converged_);
}

std::vector<int> diagonal_offsets(const Eigen::SparseMatrix<double>& A) {
  std::vector<int> offsets(static_cast<std::size_t>(A.cols()));
  const int* inner = A.innerIndexPtr();
  for (int k = 0; k < A.cols(); ++k) {
    const int* first =
        std::lower_bound(inner + A.outerIndexPtr()[k], inner + A.outerIndexPtr()[k + 1], k);
    offsets[k] = static_cast<int>(first - inner);
  }
  return offsets;
}

namespace {

// v_i <- S_i v_i on the constrained nodes: the PPCG projection onto the free subspace.
void filter(const std::vector<NodeConstraint>& constraints, Eigen::VectorXd& v) {
  for (const auto& c : constraints) v.segment<3>(3 * c.node) = c.filter * v.segment<3>(3 * c.node);
}

// The work vectors sized (they allocate on the first solve only: the sizes never change) and
// Jacobi from the diagonal, read through the offsets: no search, no copy of A.
void prepare(const Eigen::SparseMatrix<double>& A, const std::vector<int>& diagonal_offsets,
             PcgWorkspace& work) {
  const Eigen::Index n = A.cols();
  auto& [r, s, p, q, inverse_diagonal] = work;
  r.resize(n);
  s.resize(n);
  p.resize(n);
  q.resize(n);
  inverse_diagonal.resize(n);
  const double* values = A.valuePtr();
  for (Eigen::Index k = 0; k < n; ++k) {
    const double d = values[diagonal_offsets[k]];
    inverse_diagonal[k] = d != 0.0 ? 1.0 / d : 1.0;  // as Eigen's DiagonalPreconditioner
  }
}

}  // namespace

SolveStats pcg_solve(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b,
                     const std::vector<NodeConstraint>& constraints,
                     const std::vector<int>& diagonal_offsets, const SolverSettings& settings,
                     PcgWorkspace& work, Eigen::VectorXd& y) {
  prepare(A, diagonal_offsets, work);
  auto& [r, s, p, q, inverse_diagonal] = work;
  SolveStats result;
  const double rhs_norm2 = b.squaredNorm();
  if (rhs_norm2 == 0.0) {  // as Eigen: the solution of A y = 0 is 0
    y.setZero();
    result.converged = true;
    return result;
  }
  // Every product writes into q with noalias(): without it Eigen would evaluate the product
  // into a temporary first, in case q appeared on the right. A is symmetric, so A p = A^T p,
  // and the transposed view is a row-major product: a gather, each q_i written once. That is
  // what ConjugateGradient<M, Lower|Upper> does too (TransposeInput in ConjugateGradient.h).
  // On one core it buys no speed: both of Eigen's kernels are scalar loops
  // (sparse_time_dense_product_impl in SparseDenseProduct.h). Its gain is that rows can be
  // split over threads, which Eigen does with OpenMP when Eigen::nbThreads() > 1: the
  // programs step this chapter on one thread (on_one_thread, common/stepper.hpp).
  filter(constraints, y);
  q.noalias() = A.transpose() * y;
  r = b - q;
  filter(constraints, r);
  const double threshold = std::max(settings.tolerance * settings.tolerance * rhs_norm2,
                                    std::numeric_limits<double>::min());
  double residual_norm2 = r.squaredNorm();
  if (residual_norm2 >= threshold) {
    p = inverse_diagonal.cwiseProduct(r);
    filter(constraints, p);
    double rho = r.dot(p);
    while (result.iterations < settings.max_iterations) {
      q.noalias() = A.transpose() * p;
      const double step = rho / p.dot(q);
      y += step * p;
      r -= step * q;
      filter(constraints, r);
      ++result.iterations;
      residual_norm2 = r.squaredNorm();
      if (residual_norm2 < threshold) break;
      s = inverse_diagonal.cwiseProduct(r);
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

}  // namespace fem::ch06
