// Chapter 07's block-Jacobi PCG: the loop of chapter 06, with a 3x3 block per node.
#include "chapters/07_block_sparse/block_pcg.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

namespace fem::ch07 {

namespace {

// v_i <- S_i v_i on the constrained nodes: the PPCG projection onto the free subspace.
void filter(const std::vector<NodeConstraint>& constraints, Eigen::VectorXd& v) {
  for (const auto& c : constraints) v.segment<3>(3 * c.node) = c.filter * v.segment<3>(3 * c.node);
}

// s_i = D_i^-1 r_i with D_i the 3x3 diagonal block: block Jacobi.
void precondition(const std::vector<Eigen::Matrix3d>& inverse_diagonal, const Eigen::VectorXd& r,
                  Eigen::VectorXd& s) {
  for (std::size_t i = 0; i < inverse_diagonal.size(); ++i)
    s.segment<3>(3 * i).noalias() = inverse_diagonal[i] * r.segment<3>(3 * i);
}

// The diagonal blocks of the filtered matrix are symmetric positive definite (a fixed node's
// is the identity), so each has an inverse: a fixed-size 3x3 inverse, no search.
void invert_diagonal(const BlockSparseMatrix& A, const std::vector<int>& diagonal_block,
                     std::vector<Eigen::Matrix3d>& inverse_diagonal) {
  inverse_diagonal.resize(diagonal_block.size());
  for (std::size_t i = 0; i < diagonal_block.size(); ++i)
    inverse_diagonal[i] = A.blocks[diagonal_block[i]].inverse();
}

}  // namespace

SolveStats pcg_solve(const BlockSparseMatrix& A, const std::vector<int>& diagonal_block,
                     const Eigen::VectorXd& b, const std::vector<NodeConstraint>& constraints,
                     const SolverSettings& settings, PcgWorkspace& work, Eigen::VectorXd& y) {
  auto& [r, s, p, q, inverse_diagonal] = work;
  for (Eigen::VectorXd* v : {&r, &s, &p, &q}) v->resize(b.size());  // allocates once
  invert_diagonal(A, diagonal_block, inverse_diagonal);

  SolveStats result;
  const double rhs_norm2 = b.squaredNorm();
  if (rhs_norm2 == 0.0) {  // as Eigen: the solution of A y = 0 is 0
    y.setZero();
    result.converged = true;
    return result;
  }
  filter(constraints, y);
  A.multiply(y, q);
  r = b - q;
  filter(constraints, r);
  const double threshold = std::max(settings.tolerance * settings.tolerance * rhs_norm2,
                                    std::numeric_limits<double>::min());
  double residual_norm2 = r.squaredNorm();
  if (residual_norm2 >= threshold) {
    precondition(inverse_diagonal, r, p);
    filter(constraints, p);
    double rho = r.dot(p);
    while (result.iterations < settings.max_iterations) {
      A.multiply(p, q);
      const double step = rho / p.dot(q);
      // An overflowing system (an absurd E) overflows here: stop before y does, with a
      // residual that says so, rather than iterate on NaN up to the cap.
      if (!std::isfinite(step)) {
        residual_norm2 = std::numeric_limits<double>::quiet_NaN();
        break;
      }
      y += step * p;
      r -= step * q;
      filter(constraints, r);
      ++result.iterations;
      residual_norm2 = r.squaredNorm();
      if (residual_norm2 < threshold) break;
      precondition(inverse_diagonal, r, s);
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

}  // namespace fem::ch07
