// Chapter 09: one linearized backward Euler step (Baraff & Witkin 1998),
//   A dv = b,  A = M - h df/dv - h^2 df/dx,  b = h (f + h df/dx v),
// with velocity constraints by the filter S of the PPCG method (Tamstorf et al. 2015):
//   (S A S^T + I - S) y = S (b - A z),  dv = y + z.
// Chapter 09 changes who does the work: every phase runs on all the threads OpenMP is
// given. Three rules keep it correct and the result independent of the thread count:
//  - a thread writes only what it owns: the rows of its chunks, or its elements;
//  - every parallel loop over rows goes over the same fixed chunks (RowChunks);
//  - a sum over the mesh is a sum of per-chunk sums added in chunk order, never an
//    OpenMP reduction (whose order of combination depends on the threads).
#include "chapters/09_threads/stepper.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "chapters/09_threads/parallel.hpp"

namespace fem::ch09 {

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

void BlockSparseMatrix::multiply_rows(const Eigen::VectorXd& x, Eigen::VectorXd& y, int first,
                                      int last) const {
  for (int i = first; i < last; ++i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();  // in registers: y_i is written once
    for (int k = row_start[i]; k < row_start[i + 1]; ++k)
      sum.noalias() += blocks[k] * x.segment<3>(3 * column[k]);
    y.segment<3>(3 * i) = sum;
  }
}

void BlockSparseMatrix::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  multiply_rows(x, y, 0, block_rows());
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

RowChunks::RowChunks(const BlockSparseMatrix& pattern) {
  // Equal numbers of blocks rather than of rows: the SpMV, the largest loop, costs per
  // block. The boundaries depend on the pattern only.
  const int rows = pattern.block_rows();
  const long long blocks = pattern.row_start.back();
  start.assign(kCount + 1, rows);
  start[0] = 0;
  int i = 0;
  for (int c = 1; c < kCount; ++c) {
    const long long target = blocks * c / kCount;
    while (i < rows && pattern.row_start[i] < target) ++i;
    start[c] = i;
  }
}

namespace {

// The sum of per-chunk partial sums, in chunk order. Every thread adds them up itself
// after the barrier (64 additions): the same value on every thread, and no extra barrier
// to hand a result from one thread to the others.
double sum_in_order(const std::vector<double>& partial) {
  double sum = 0.0;
  for (const double p : partial) sum += p;
  return sum;
}

}  // namespace

// ---- the stepper ------------------------------------------------------------------------

ThreadsStepper::ThreadsStepper(const Scene& scene, const SolverSettings& settings,
                               ElementParallelism element_parallelism)
    : Stepper(scene),
      scene_(scene),
      model_(scene),
      settings_(settings),
      element_parallelism_(element_parallelism) {
  const int n = model_.dofs;
  const int num_elements = static_cast<int>(model_.tets.size());
  rotations_.resize(num_elements);
  element_forces_.resize(num_elements);
  f_.resize(n);

  // The pattern, once: a block per pair of nodes that share a tetrahedron. Where each
  // element's 16 blocks sit, the diagonal blocks and the transposes are found once too.
  dfdx_ = BlockSparseMatrix(node_adjacency(scene.mesh));
  A_ = dfdx_;
  chunks_ = RowChunks(dfdx_);
  element_blocks_.resize(num_elements);
  for (int e = 0; e < num_elements; ++e)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        element_blocks_[e][4 * a + b] = dfdx_.find(model_.tets[e][a], model_.tets[e][b]);
  diagonal_block_.resize(model_.num_nodes);
  for (int i = 0; i < model_.num_nodes; ++i) diagonal_block_[i] = dfdx_.find(i, i);
  transpose_block_.resize(dfdx_.blocks.size());
  for (int i = 0; i < model_.num_nodes; ++i)
    for (int k = dfdx_.row_start[i]; k < dfdx_.row_start[i + 1]; ++k)
      transpose_block_[k] = dfdx_.find(dfdx_.column[k], i);

  // The gather tables: the element-to-block table read the other way round, by node and
  // by block. Filled in element order, so that each sum adds in the serial order.
  const auto invert = [](int rows, int terms, const auto& target, std::vector<int>& start,
                         std::vector<int>& list) {
    start.assign(rows + 1, 0);
    for (int t = 0; t < terms; ++t) ++start[target(t) + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    list.resize(terms);
    std::vector<int> next(start.begin(), start.end() - 1);
    for (int t = 0; t < terms; ++t) list[next[target(t)]++] = t;
  };
  invert(model_.num_nodes, 4 * num_elements,
         [this](int t) { return model_.tets[t / 4][t % 4]; }, node_corner_start_, node_corners_);
  invert(static_cast<int>(dfdx_.blocks.size()), 16 * num_elements,
         [this](int t) { return element_blocks_[t / 16][t % 16]; }, block_term_start_,
         block_terms_);

  // The colouring, of groups of kGroup consecutive elements rather than of elements: a
  // group keeps the mesh order's locality (its elements share nodes, hence cache lines),
  // and a colour holds groups that share no node. Greedily, each group takes the first
  // colour that no group sharing one of its nodes has.
  const int groups = (num_elements + kGroup - 1) / kGroup;
  std::vector<std::vector<int>> node_colours(model_.num_nodes);
  std::vector<int> colour(groups);
  int colours = 0;
  for (int g = 0; g < groups; ++g) {
    const int first = g * kGroup, last = std::min(num_elements, first + kGroup);
    const auto taken = [&](int candidate) {
      for (int e = first; e < last; ++e)
        for (int a = 0; a < 4; ++a) {
          const auto& used = node_colours[model_.tets[e][a]];
          if (std::find(used.begin(), used.end(), candidate) != used.end()) return true;
        }
      return false;
    };
    int c = 0;
    while (taken(c)) ++c;
    colour[g] = c;
    colours = std::max(colours, c + 1);
    for (int e = first; e < last; ++e)
      for (int a = 0; a < 4; ++a) node_colours[model_.tets[e][a]].push_back(c);
  }
  invert(colours, groups, [&colour](int g) { return colour[g]; }, colour_start_, colour_order_);

  pcg_ = ParallelPcg(dfdx_, diagonal_block_, scene_.constraints);
  y_.setZero(n);
}

void ThreadsStepper::step(State& state) {
  PhaseTimer total(profile_.step);
  {
    PhaseTimer t(profile_.forces);
    compute_forces(state);
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

void ThreadsStepper::compute_forces(const State& state) {
  const int num_elements = static_cast<int>(model_.tets.size());
  const auto element = [&](int e) {
    const Vector12d xe = gather(state.x, model_.tets[e]);
    rotations_[e] = polar_rotation(deformation_gradient(model_.rest[e], xe));
    return element_force(model_.rest[e], rotations_[e], xe);
  };
  run_parallel([&] {
    if (element_parallelism_ == ElementParallelism::gather) {
      // Every element on its own (no shared writes), then every node sums its corners.
#pragma omp for schedule(static)
      for (int e = 0; e < num_elements; ++e) element_forces_[e] = element(e);
#pragma omp for schedule(static)
      for (int c = 0; c < chunks_.count(); ++c)
        for (int i = chunks_.start[c]; i < chunks_.start[c + 1]; ++i) {
          Eigen::Vector3d sum = model_.gravity_force.segment<3>(3 * i);
          for (int k = node_corner_start_[i]; k < node_corner_start_[i + 1]; ++k)
            sum += element_forces_[node_corners_[k] / 4].segment<3>(3 * (node_corners_[k] % 4));
          f_.segment<3>(3 * i) = sum;
        }
    } else {
#pragma omp for schedule(static)
      for (int c = 0; c < chunks_.count(); ++c)
        for (int i = chunks_.start[c]; i < chunks_.start[c + 1]; ++i)
          f_.segment<3>(3 * i) = model_.gravity_force.segment<3>(3 * i);
      for (int colour = 0; colour < colours(); ++colour) {
        // The barrier at the end of each loop orders the colours: no two threads ever
        // add into the same node at the same time.
#pragma omp for schedule(static)
        for (int k = colour_start_[colour]; k < colour_start_[colour + 1]; ++k)
          for (int e = group_first(colour_order_[k]); e < group_last(colour_order_[k]); ++e) {
            const Vector12d fe = element(e);
            for (int a = 0; a < 4; ++a)
              f_.segment<3>(3 * model_.tets[e][a]) += fe.segment<3>(3 * a);
          }
      }
    }
  });
}

void ThreadsStepper::build_dfdx() {
  run_parallel([&] {
    if (element_parallelism_ == ElementParallelism::gather) {
      // Each block sums its elements' terms, in element order, on the thread of its row.
#pragma omp for schedule(static)
      for (int c = 0; c < chunks_.count(); ++c)
        for (int k = dfdx_.row_start[chunks_.start[c]]; k < dfdx_.row_start[chunks_.start[c + 1]];
             ++k) {
          Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
          for (int t = block_term_start_[k]; t < block_term_start_[k + 1]; ++t) {
            const int e = block_terms_[t] / 16, ab = block_terms_[t] % 16;
            sum += dfdx_block(model_.rest[e], rotations_[e], ab / 4, ab % 4);
          }
          dfdx_.blocks[k] = sum;
        }
    } else {
#pragma omp for schedule(static)
      for (int c = 0; c < chunks_.count(); ++c)
        for (int k = dfdx_.row_start[chunks_.start[c]]; k < dfdx_.row_start[chunks_.start[c + 1]];
             ++k)
          dfdx_.blocks[k].setZero();
      for (int colour = 0; colour < colours(); ++colour) {
#pragma omp for schedule(static)
        for (int k = colour_start_[colour]; k < colour_start_[colour + 1]; ++k)
          for (int e = group_first(colour_order_[k]); e < group_last(colour_order_[k]); ++e)
            for (int ab = 0; ab < 16; ++ab)
              dfdx_.blocks[element_blocks_[e][ab]] +=
                  dfdx_block(model_.rest[e], rotations_[e], ab / 4, ab % 4);
      }
    }
  });
}

void ThreadsStepper::compose_system(const State& state) {
  const double h = scene_.dt;
  const double alpha = scene_.damping.alpha, beta = scene_.damping.beta;
  const double stiffness_factor = -(h * beta + h * h);
  const double mass_factor = 1.0 + h * alpha;
  b_.resize(model_.dofs);
  // Row by row, on the thread that owns the row:
  //   A_ij = (1 + h alpha) M_ij - (h beta + h^2) df/dx_ij,
  //   b_i = h (f_i - alpha M_i v_i) + h sum_j df/dx_ij ((h + beta) v_j).
  run_parallel([&] {
#pragma omp for schedule(static)
    for (int c = 0; c < chunks_.count(); ++c)
      for (int i = chunks_.start[c]; i < chunks_.start[c + 1]; ++i) {
        Eigen::Vector3d dfdx_v = Eigen::Vector3d::Zero();
        for (int k = dfdx_.row_start[i]; k < dfdx_.row_start[i + 1]; ++k) {
          A_.blocks[k] = stiffness_factor * dfdx_.blocks[k];
          dfdx_v.noalias() += dfdx_.blocks[k] * ((h + beta) * state.v.segment<3>(3 * dfdx_.column[k]));
        }
        const Eigen::Vector3d m = model_.lumped_mass.segment<3>(3 * i);
        A_.blocks[diagonal_block_[i]].diagonal() += mass_factor * m;
        b_.segment<3>(3 * i) = h * dfdx_v + h * f_.segment<3>(3 * i) -
                               (h * alpha) * m.cwiseProduct(state.v.segment<3>(3 * i));
      }
  });
  b_ += h * f_ext_;  // a few nonzeros: not worth a thread
}

void ThreadsStepper::apply_constraints(const State& state) {
  // A few hundred constrained nodes at most, about 1% of the step: one thread (Amdahl's
  // serial fraction, small enough to keep the code as it was).
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

  // S A S^T + I - S in place: a row of blocks is contiguous, and the column blocks a_ji
  // are the transposes' positions of the row.
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

void ThreadsStepper::solve() {
  // Warm start: y_ still holds the previous step's answer; the solver filters it.
  const PcgResult result = pcg_.solve(A_, filtered_b_, settings_, y_);
  dv_ = y_;
  dv_ += z_;
  profile_.cg_iterations = result.iterations;
  profile_.relative_residual = result.relative_residual;
  profile_.converged = result.converged;
  report_if_not_converged(profile_, settings_, "09_threads", warned_not_converged_);
}

// ---- the solver ---------------------------------------------------------------------------

ParallelPcg::ParallelPcg(const BlockSparseMatrix& pattern, const std::vector<int>& diagonal_block,
                         const std::vector<NodeConstraint>& constraints)
    : chunks_(pattern), diagonal_block_(diagonal_block) {
  // The constraints of each chunk, in node order.
  chunk_constraints_ = constraints;  // a copy: the solver outlives no one's scene
  std::stable_sort(chunk_constraints_.begin(), chunk_constraints_.end(),
                   [](const NodeConstraint& a, const NodeConstraint& b) { return a.node < b.node; });
  chunk_constraint_start_.assign(chunks_.count() + 1, 0);
  for (int c = 0, k = 0; c < chunks_.count(); ++c) {
    while (k < static_cast<int>(chunk_constraints_.size()) &&
           chunk_constraints_[k].node < chunks_.start[c + 1])
      ++k;
    chunk_constraint_start_[c + 1] = k;
  }
  inverse_diagonal_.resize(pattern.block_rows());
  for (auto* partial : {&partial_bb_, &partial_pq_, &partial_rr_, &partial_rs_})
    partial->assign(chunks_.count(), 0.0);
}

PcgResult ParallelPcg::solve(const BlockSparseMatrix& A, const Eigen::VectorXd& b,
                             const SolverSettings& settings, Eigen::VectorXd& y) {
  const Eigen::Index n = b.size();
  // Same sizes every step: these resizes allocate on the first solve only.
  r_.resize(n);
  s_.resize(n);
  p_.resize(n);
  q_.resize(n);
  const int chunks = chunks_.count();
  const std::vector<int>& start = chunks_.start;
  // v_i <- S_i v_i on the constrained nodes of chunk c: the PPCG projection onto the free
  // subspace.
  const auto filter = [this](int c, Eigen::VectorXd& v) {
    for (int k = chunk_constraint_start_[c]; k < chunk_constraint_start_[c + 1]; ++k) {
      const NodeConstraint& constraint = chunk_constraints_[k];
      v.segment<3>(3 * constraint.node) = constraint.filter * v.segment<3>(3 * constraint.node);
    }
  };
  // s_i = D_i^-1 r_i with D_i the 3x3 diagonal block: block Jacobi.
  const auto precondition = [this](int first, int last, const Eigen::VectorXd& r,
                                   Eigen::VectorXd& s) {
    for (int i = first; i < last; ++i)
      s.segment<3>(3 * i).noalias() = inverse_diagonal_[i] * r.segment<3>(3 * i);
  };

  PcgResult result;
  run_parallel([&] {
    // Everything below runs on every thread; a `#pragma omp for` shares its chunks out and
    // ends with a barrier. The scalars (norms, rho, the step) are each thread's own copy,
    // added up from the same partial sums in the same order: equal on every thread, so
    // every thread takes the same branches.

    // The block-Jacobi inverses (the diagonal blocks of the filtered matrix are symmetric
    // positive definite: a fixed-size 3x3 inverse each), the filtered guess, ||b||^2.
#pragma omp for schedule(static)
    for (int c = 0; c < chunks; ++c) {
      for (int i = start[c]; i < start[c + 1]; ++i)
        inverse_diagonal_[i] = A.blocks[diagonal_block_[i]].inverse();
      filter(c, y);
      partial_bb_[c] = b.segment(3 * start[c], 3 * (start[c + 1] - start[c])).squaredNorm();
    }
    const double rhs_norm2 = sum_in_order(partial_bb_);
    const double threshold = std::max(settings.tolerance * settings.tolerance * rhs_norm2,
                                      std::numeric_limits<double>::min());
    if (rhs_norm2 == 0.0) {  // as Eigen: the solution of A y = 0 is 0
#pragma omp for schedule(static)
      for (int c = 0; c < chunks; ++c)
        y.segment(3 * start[c], 3 * (start[c + 1] - start[c])).setZero();
#pragma omp master
      result.converged = true;
      return;
    }

    // r = S (b - A y), p = S D^-1 r, with ||r||^2 and rho = r . p, chunk by chunk.
#pragma omp for schedule(static)
    for (int c = 0; c < chunks; ++c) {
      const int first = start[c], size = 3 * (start[c + 1] - start[c]);
      A.multiply_rows(y, q_, start[c], start[c + 1]);
      r_.segment(3 * first, size) = b.segment(3 * first, size) - q_.segment(3 * first, size);
      filter(c, r_);
      precondition(start[c], start[c + 1], r_, p_);
      filter(c, p_);
      partial_rr_[c] = r_.segment(3 * first, size).squaredNorm();
      partial_rs_[c] = r_.segment(3 * first, size).dot(p_.segment(3 * first, size));
    }
    double residual_norm2 = sum_in_order(partial_rr_);
    double rho = sum_in_order(partial_rs_);
    int iterations = 0;
    while (residual_norm2 >= threshold && iterations < settings.max_iterations) {
      // q = A p and p . q: the SpMV reads p of the neighbouring rows, hence the barrier
      // before it (at the end of the previous update of p).
#pragma omp for schedule(static)
      for (int c = 0; c < chunks; ++c) {
        const int first = start[c], size = 3 * (start[c + 1] - start[c]);
        A.multiply_rows(p_, q_, start[c], start[c + 1]);
        partial_pq_[c] = p_.segment(3 * first, size).dot(q_.segment(3 * first, size));
      }
      const double step = rho / sum_in_order(partial_pq_);
      // Every vector operation of the iteration that needs no neighbour, on one chunk at a
      // time while it sits in L1: y += step p, r -= step q, r filtered, s = S D^-1 r,
      // ||r||^2 and r . s. Each is an Eigen expression on the chunk's segment, so it keeps
      // the SIMD of the whole-vector operations of the chapters before.
#pragma omp for schedule(static)
      for (int c = 0; c < chunks; ++c) {
        const int first = start[c], size = 3 * (start[c + 1] - start[c]);
        y.segment(3 * first, size) += step * p_.segment(3 * first, size);
        r_.segment(3 * first, size) -= step * q_.segment(3 * first, size);
        filter(c, r_);
        precondition(start[c], start[c + 1], r_, s_);
        filter(c, s_);
        partial_rr_[c] = r_.segment(3 * first, size).squaredNorm();
        partial_rs_[c] = r_.segment(3 * first, size).dot(s_.segment(3 * first, size));
      }
      ++iterations;
      residual_norm2 = sum_in_order(partial_rr_);
      if (residual_norm2 < threshold) break;
      const double rho_old = rho;
      rho = sum_in_order(partial_rs_);
      const double beta = rho / rho_old;
#pragma omp for schedule(static)
      for (int c = 0; c < chunks; ++c) {
        const int first = start[c], size = 3 * (start[c + 1] - start[c]);
        p_.segment(3 * first, size) = s_.segment(3 * first, size) + beta * p_.segment(3 * first, size);
      }
    }
#pragma omp master
    {
      result.iterations = iterations;
      result.relative_residual = std::sqrt(residual_norm2 / rhs_norm2);
      result.converged = residual_norm2 < threshold;
    }
  });
  return result;
}

}  // namespace fem::ch09
