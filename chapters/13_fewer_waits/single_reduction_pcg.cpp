// Chapter 13: Chronopoulos and Gear's PCG on the fused V-cycle (see single_reduction_pcg.hpp).
//   s = S M r, w = A s, gamma = r . s, delta = s . w               (the cycle, one loop)
//   beta = gamma / gamma_old, alpha = gamma / (delta - beta gamma / alpha_old)
//   p = s + beta p, q = w + beta q, y += alpha p, r -= alpha q      (one loop, with M's entry)
// In exact arithmetic the same iterates as chapter 09's PCG: delta - beta gamma / alpha_old
// is p . A p written with the new sums only.
#include "chapters/13_fewer_waits/single_reduction_pcg.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "chapters/09_threads/parallel.hpp"

namespace fem::ch13 {

void SingleReductionPcg::set_constraints(const std::vector<NodeConstraint>& constraints) {
  ch09::constraints_by_part(constraints, part_, constraints_, constraint_start_);
}

SingleReductionPcg::SingleReductionPcg(const std::vector<int>& part,
                                       const std::vector<NodeConstraint>& constraints)
    : part_(part) {
  set_constraints(constraints);
  const int parts = static_cast<int>(part_.size()) - 1;
  for (auto* partial : {&partial_bb_, &partial_rr_, &partial_gamma_, &partial_delta_})
    partial->assign(parts, 0.0);
}

double SingleReductionPcg::sum(const std::vector<double>& partial) const {
  double total = 0.0;  // in part order on every thread: the same bits for any team
  for (const double p : partial) total += p;
  return total;
}

SolveStats SingleReductionPcg::solve(const ch07::BlockSparseMatrix& A, ch08::ProductPart& product,
                                     FusedVCycle& M, const Eigen::VectorXd& b,
                                     const SolverSettings& settings, Eigen::VectorXd& y) {
  for (Eigen::VectorXd* v : {&r_, &s_, &w_, &p_, &q_}) v->resize(b.size());  // allocates once
  SolveStats result;
  ch09::run_parallel([&] {
    product.prepare(A);
    M.prepare(A);  // the hierarchy shares out its own row blocks
    const double rhs_norm2 = start(product, M, b, y);
    const SolveStats stats = iterate(product, M, rhs_norm2, settings, y);
#pragma omp master
    result = stats;
  });
  return result;
}

double SingleReductionPcg::start(const ch08::ProductPart& A, FusedVCycle& M,
                                 const Eigen::VectorXd& b, Eigen::VectorXd& y) {
  for (const int p : ch09::StaticShare(static_cast<int>(part_.size()) - 1)) {
    filter(p)(y);
    const int first = 3 * part_[p], size = 3 * (part_[p + 1] - part_[p]);
    partial_bb_[p] = b.segment(first, size).squaredNorm();
  }
  // r = S (b - A y) reads y's neighbours: after the barrier above.
  for (const int p : ch09::StaticShare(static_cast<int>(part_.size()) - 1)) {
    const int first = 3 * part_[p], size = 3 * (part_[p + 1] - part_[p]);
    A.multiply_rows(y, w_, part_[p], part_[p + 1]);
    r_.segment(first, size) = b.segment(first, size) - w_.segment(first, size);
    filter(p)(r_);
    partial_rr_[p] = r_.segment(first, size).squaredNorm();
    M.enter(part_[p], part_[p + 1], r_);
  }
  return sum(partial_bb_);
}

SolveStats SingleReductionPcg::iterate(const ch08::ProductPart& A, FusedVCycle& M, double rhs_norm2,
                                       const SolverSettings& settings, Eigen::VectorXd& y) {
  SolveStats stats;
  if (rhs_norm2 == 0.0) {  // as Eigen: the solution of A y = 0 is 0
    for (const int p : ch09::StaticShare(static_cast<int>(part_.size()) - 1))
      y.segment(3 * part_[p], 3 * (part_[p + 1] - part_[p])).setZero();
    stats.converged = true;
    return stats;
  }
  const double threshold = std::max(settings.tolerance * settings.tolerance * rhs_norm2,
                                    std::numeric_limits<double>::min());
  double residual_norm2 = sum(partial_rr_), gamma_old = 0.0, alpha = 0.0;
  while (residual_norm2 >= threshold && stats.iterations < settings.max_iterations) {
    const Sums sums = precondition_and_product(A, M);
    const double beta = stats.iterations == 0 ? 0.0 : sums.gamma / gamma_old;
    const double denominator =
        sums.delta - (stats.iterations == 0 ? 0.0 : beta * sums.gamma / alpha);
    alpha = sums.gamma / denominator;
    // An overflowing system stops here with a residual that says so (every thread alike).
    if (!std::isfinite(alpha)) {
      residual_norm2 = std::numeric_limits<double>::quiet_NaN();
      break;
    }
    gamma_old = sums.gamma;
    residual_norm2 = update(M, alpha, beta, y);
    ++stats.iterations;
  }
  stats.relative_residual = std::sqrt(residual_norm2 / rhs_norm2);
  stats.converged = residual_norm2 < threshold;
  return stats;
}

SingleReductionPcg::Sums SingleReductionPcg::precondition_and_product(const ch08::ProductPart& A,
                                                                      FusedVCycle& M) {
  // s = S M r; gamma's parts as each thread's last smoothing step writes its rows of s.
  const auto finish = [&](int first, int last) {
    const int p = static_cast<int>(std::lower_bound(part_.begin(), part_.end(), first) -
                                   part_.begin());  // the row block that starts at first
    filter(p)(s_);
    const int f = 3 * first, size = 3 * (last - first);
    partial_gamma_[p] = r_.segment(f, size).dot(s_.segment(f, size));
  };
  M.complete(s_, finish);
  // w = A s reads s's neighbours: after the cycle's last barrier.
  for (const int p : ch09::StaticShare(static_cast<int>(part_.size()) - 1))
    partial_delta_[p] = single_reduction_product(A, s_, w_, part_[p], part_[p + 1]);
  return {0.0, sum(partial_gamma_), sum(partial_delta_)};
}

double SingleReductionPcg::update(FusedVCycle& M, double alpha, double beta, Eigen::VectorXd& y) {
  // Row-local work only: the recurrences, the new residual and the next cycle's first step
  // on it (wasted on the last iteration, which nobody knows is the last until ||r|| is summed).
  for (const int p : ch09::StaticShare(static_cast<int>(part_.size()) - 1)) {
    partial_rr_[p] = single_reduction_update(alpha, beta, s_, w_, p_, q_, y, r_, filter(p),
                                             part_[p], part_[p + 1]);
    M.enter(part_[p], part_[p + 1], r_);
  }
  return sum(partial_rr_);
}

double single_reduction_product(const ch08::ProductPart& A, const Eigen::VectorXd& s,
                                Eigen::VectorXd& w, int first, int last) {
  A.multiply_rows(s, w, first, last);
  const int f = 3 * first, size = 3 * (last - first);
  return s.segment(f, size).dot(w.segment(f, size));
}

double single_reduction_update(double alpha, double beta, const Eigen::VectorXd& s,
                               const Eigen::VectorXd& w, Eigen::VectorXd& p, Eigen::VectorXd& q,
                               Eigen::VectorXd& y, Eigen::VectorXd& r,
                               const ch09::ChunkFilter& filter, int first, int last) {
  const int f = 3 * first, size = 3 * (last - first);
  if (beta == 0.0) {
    p.segment(f, size) = s.segment(f, size);
    q.segment(f, size) = w.segment(f, size);
  } else {
    p.segment(f, size) = s.segment(f, size) + beta * p.segment(f, size);
    q.segment(f, size) = w.segment(f, size) + beta * q.segment(f, size);
  }
  y.segment(f, size) += alpha * p.segment(f, size);
  r.segment(f, size) -= alpha * q.segment(f, size);
  filter(r);
  return r.segment(f, size).squaredNorm();
}

}  // namespace fem::ch13
