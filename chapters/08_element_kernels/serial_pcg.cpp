// Chapter 08's serial PCG: chapter 07's block PCG (block_pcg.cpp), its product and its
// preconditioner called through their faces.
#include "chapters/08_element_kernels/serial_pcg.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fem::ch08 {

namespace {

// v_i <- S_i v_i on the constrained nodes: the PPCG projection onto the free subspace.
void filter(const std::vector<NodeConstraint>& constraints, Eigen::VectorXd& v) {
  for (const auto& c : constraints) v.segment<3>(3 * c.node) = c.filter * v.segment<3>(3 * c.node);
}

}  // namespace

SolveStats serial_pcg(const BlockSparseMatrix& A, ProductPart& product,
                      PreconditionerPart& preconditioner, const Eigen::VectorXd& b,
                      const std::vector<NodeConstraint>& constraints,
                      const SolverSettings& settings, PcgVectors& vectors, Eigen::VectorXd& y) {
  auto& [r, s, p, q] = vectors;
  for (Eigen::VectorXd* v : {&r, &s, &p, &q}) v->resize(b.size());  // allocates once
  const int rows = A.block_rows();
  product.prepare(A);
  preconditioner.prepare(A);

  SolveStats result;
  const double rhs_norm2 = b.squaredNorm();
  if (rhs_norm2 == 0.0) {  // as Eigen: the solution of A y = 0 is 0
    y.setZero();
    result.converged = true;
    return result;
  }
  filter(constraints, y);
  product.multiply_rows(y, q, 0, rows);
  r = b - q;
  filter(constraints, r);
  const double threshold = std::max(settings.tolerance * settings.tolerance * rhs_norm2,
                                    std::numeric_limits<double>::min());
  double residual_norm2 = r.squaredNorm();
  if (residual_norm2 >= threshold) {
    preconditioner.apply(r, p);
    filter(constraints, p);
    double rho = r.dot(p);
    while (result.iterations < settings.max_iterations) {
      product.multiply_rows(p, q, 0, rows);
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
      preconditioner.apply(r, s);
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

}  // namespace fem::ch08
