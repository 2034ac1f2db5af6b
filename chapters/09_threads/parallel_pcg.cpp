// Chapter 09's parallel PCG: one parallel region per solve, one shared loop (StaticShare)
// over the fixed chunks per step of the iteration, sums in chunk order.
#include "chapters/09_threads/parallel_pcg.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "chapters/09_threads/parallel.hpp"

namespace fem::ch09 {

RowChunks::RowChunks(const BlockSparseMatrix& pattern)
    // Fewer chunks on a small mesh (kMinRows rows each on average), where a chunk's fixed cost
    // would show; still a function of the mesh alone.
    : start(equal_block_partition(pattern.row_start,
                                  std::clamp(pattern.block_rows() / kMinRows, 1, kMaxCount))) {}

double sum_in_order(const std::vector<double>& partial) {
  double sum = 0.0;
  for (const double p : partial) sum += p;
  return sum;
}

// ---- the kernels -------------------------------------------------------------------------

double pcg_product(const ch08::ProductPart& A, const Eigen::VectorXd& p, Eigen::VectorXd& q,
                   int first, int last) {
  A.multiply_rows(p, q, first, last);
  return p.segment(3 * first, 3 * (last - first)).dot(q.segment(3 * first, 3 * (last - first)));
}

double pcg_update(double step, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                  Eigen::VectorXd& y, Eigen::VectorXd& r, const ChunkFilter& filter, int first,
                  int last) {
  // Every vector operation of the iteration that needs no neighbour, on one chunk at a time
  // while it sits in L1. Each is an Eigen expression on the chunk's segment, so it keeps the
  // SIMD of the whole-vector operations of the chapters before.
  const int f = 3 * first, size = 3 * (last - first);
  y.segment(f, size) += step * p.segment(f, size);
  r.segment(f, size) -= step * q.segment(f, size);
  filter(r);
  return r.segment(f, size).squaredNorm();
}

void pcg_next_direction(double beta, const Eigen::VectorXd& s, Eigen::VectorXd& p, int first,
                        int last) {
  const int f = 3 * first, size = 3 * (last - first);
  p.segment(f, size) = s.segment(f, size) + beta * p.segment(f, size);
}

// ---- the solver ---------------------------------------------------------------------------

void ParallelPcg::set_constraints(const std::vector<NodeConstraint>& constraints) {
  constraints_by_part(constraints, chunks_.start, constraints_, constraint_start_);
}

void constraints_by_part(const std::vector<NodeConstraint>& constraints,
                         const std::vector<int>& start, std::vector<NodeConstraint>& sorted,
                         std::vector<int>& first) {
  // A copy (no reference into a scene) into `sorted`'s own storage, sorted by node. Not
  // std::stable_sort: its temporary buffer is an allocation a call, and an app that drags a
  // node changes the constraints every frame. std::sort keeps no order among equal keys, so
  // the key is the node and then the kind: a node's constraints (a node named twice) are
  // projections, applied in an order that does not depend on where they came in the list.
  sorted.assign(constraints.begin(), constraints.end());
  std::sort(sorted.begin(), sorted.end(), [](const NodeConstraint& a, const NodeConstraint& b) {
    return a.node != b.node ? a.node < b.node : a.kind < b.kind;
  });
  const int parts = static_cast<int>(start.size()) - 1;
  first.assign(parts + 1, 0);
  for (int p = 0, k = 0; p < parts; ++p) {
    while (k < static_cast<int>(sorted.size()) && sorted[k].node < start[p + 1]) ++k;
    first[p + 1] = k;
  }
}

ParallelPcg::ParallelPcg(const BlockSparseMatrix& pattern,
                         const std::vector<NodeConstraint>& constraints)
    : chunks_(pattern) {
  set_constraints(constraints);
  for (auto* partial : {&partial_bb_, &partial_pq_, &partial_rr_, &partial_rs_})
    partial->assign(chunks_.count(), 0.0);
}

SolveStats ParallelPcg::solve(const BlockSparseMatrix& A, ch08::ProductPart& product,
                              ch08::PreconditionerPart& M, const Eigen::VectorXd& b,
                              const SolverSettings& settings, Eigen::VectorXd& y) {
  for (Eigen::VectorXd* v : {&r_, &s_, &p_, &q_}) v->resize(b.size());  // allocates once
  SolveStats result;
  run_parallel([&] {
    // Everything below runs on every thread. The scalars (norms, rho, the step) are each
    // thread's own copy, added up from the same partial sums in the same order: equal on
    // every thread, so every thread takes the same branches.
    product.prepare(A);
    M.prepare(A);
    const double rhs_norm2 = filter_guess(b, y);
    const SolveStats stats = iterate(product, M, b, rhs_norm2, settings, y);
#pragma omp master
    result = stats;
  });
  return result;
}

SolveStats ParallelPcg::iterate(const Product& A, Preconditioner& M, const Eigen::VectorXd& b,
                                double rhs_norm2, const SolverSettings& settings,
                                Eigen::VectorXd& y) {
  SolveStats stats;
  if (rhs_norm2 == 0.0) {  // as Eigen: the solution of A y = 0 is 0
    for (const int c : StaticShare(chunks_.count()))
      y.segment(chunks_.first_dof(c), chunks_.dofs(c)).setZero();
    stats.converged = true;
    return stats;
  }
  const double threshold = std::max(settings.tolerance * settings.tolerance * rhs_norm2,
                                    std::numeric_limits<double>::min());
  // p = S M r; a block-diagonal M was applied inside residual().
  double residual_norm2 = residual(A, M, b, y);
  double rho = 0.0;
  if (M.block_diagonal())
    rho = sum_in_order(partial_rs_);
  else if (residual_norm2 >= threshold)
    rho = precondition(M, p_);
  while (residual_norm2 >= threshold && stats.iterations < settings.max_iterations) {
    const double step = rho / product(A);
    // An overflowing system (an absurd E) overflows here: stop before y does, with a
    // residual that says so, rather than iterate on NaN up to the cap. Every thread sees
    // the same step, so every thread stops.
    if (!std::isfinite(step)) {
      residual_norm2 = std::numeric_limits<double>::quiet_NaN();
      break;
    }
    residual_norm2 = update(M, step, y);
    ++stats.iterations;
    if (residual_norm2 < threshold) break;
    const double rho_old = rho;
    rho = M.block_diagonal() ? sum_in_order(partial_rs_) : precondition(M, s_);
    next_direction(rho / rho_old);
  }
  stats.relative_residual = std::sqrt(residual_norm2 / rhs_norm2);
  stats.converged = residual_norm2 < threshold;
  return stats;
}

void ParallelPcg::precondition_chunk(const Preconditioner& M, int c, Eigen::VectorXd& s) {
  M.apply_rows(chunks_.start[c], chunks_.start[c + 1], r_, s);
  filter(c)(s);
  partial_rs_[c] = r_.segment(chunks_.first_dof(c), chunks_.dofs(c))
                       .dot(s.segment(chunks_.first_dof(c), chunks_.dofs(c)));
}

double ParallelPcg::filter_guess(const Eigen::VectorXd& b, Eigen::VectorXd& y) {
  for (const int c : StaticShare(chunks_.count())) {
    filter(c)(y);
    partial_bb_[c] = b.segment(chunks_.first_dof(c), chunks_.dofs(c)).squaredNorm();
  }
  return sum_in_order(partial_bb_);
}

double ParallelPcg::residual(const Product& A, const Preconditioner& M, const Eigen::VectorXd& b,
                             const Eigen::VectorXd& y) {
  for (const int c : StaticShare(chunks_.count())) {
    const int first = chunks_.first_dof(c), size = chunks_.dofs(c);
    A.multiply_rows(y, q_, chunks_.start[c], chunks_.start[c + 1]);
    r_.segment(first, size) = b.segment(first, size) - q_.segment(first, size);
    filter(c)(r_);
    if (M.block_diagonal()) precondition_chunk(M, c, p_);
    partial_rr_[c] = r_.segment(first, size).squaredNorm();
  }
  return sum_in_order(partial_rr_);
}

double ParallelPcg::precondition(Preconditioner& M, Eigen::VectorXd& s) {
  // M reads r of every row: it starts after the barrier that ended r's update.
  M.apply(r_, s);
  for (const int c : StaticShare(chunks_.count())) {
    filter(c)(s);
    partial_rs_[c] = r_.segment(chunks_.first_dof(c), chunks_.dofs(c))
                         .dot(s.segment(chunks_.first_dof(c), chunks_.dofs(c)));
  }
  return sum_in_order(partial_rs_);
}

double ParallelPcg::product(const Product& A) {
  // q = A p reads p of the neighbouring rows: the barrier that ended p's update comes first.
  for (const int c : StaticShare(chunks_.count()))
    partial_pq_[c] = pcg_product(A, p_, q_, chunks_.start[c], chunks_.start[c + 1]);
  return sum_in_order(partial_pq_);
}

double ParallelPcg::update(const Preconditioner& M, double step, Eigen::VectorXd& y) {
  // y, r and ||r||^2 chunk by chunk, and for a block-diagonal M also s = S M r and r . s on the
  // chunk's rows while they sit in L1.
  for (const int c : StaticShare(chunks_.count())) {
    partial_rr_[c] =
        pcg_update(step, p_, q_, y, r_, filter(c), chunks_.start[c], chunks_.start[c + 1]);
    if (M.block_diagonal()) precondition_chunk(M, c, s_);
  }
  return sum_in_order(partial_rr_);
}

void ParallelPcg::next_direction(double beta) {
  for (const int c : StaticShare(chunks_.count()))
    pcg_next_direction(beta, s_, p_, chunks_.start[c], chunks_.start[c + 1]);
}

}  // namespace fem::ch09
