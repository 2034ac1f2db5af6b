// Chapter 10: the smoothers, on the rows [first, last) of one fixed row block, and the numbers
// they need (their diagonal, the spectral radius of D^-1 A, the polynomial weights). All three
// are parallel and symmetric in the V-cycle:
//  - GaussSeidel: l1-hybrid block Gauss-Seidel (Baker, Falgout, Kolev & Yang 2011,
//    Multigrid smoothers for ultraparallel computing): Gauss-Seidel inside each row block, Jacobi
//    between blocks, the diagonal grown by the l1 norm of the couplings to other blocks; forward
//    before the coarse correction, backward after.
//  - Chebyshev: a Chebyshev polynomial in D^-1 A (Adams, Brezina, Hu & Tuminaro 2003,
//    Parallel multigrid smoothing: polynomial versus Gauss-Seidel).
//  - Jacobi: damped block Jacobi.
#pragma once

#include <Eigen/LU>
#include <type_traits>
#include <vector>

#include "chapters/10_multigrid/level.hpp"

namespace fem::ch10 {

enum class Smoother { GaussSeidel, Chebyshev, Jacobi };

// AMGCL's `relax` parameters: what the smoother does on every level.
struct SmootherSettings {
  Smoother smoother = Smoother::Chebyshev;
  int sweeps = 1;                 // pre- and post-smoothing sweeps per level
  bool l1 = true;                 // Gauss-Seidel: the l1 term (false: plain hybrid)
  int chebyshev_degree = 3;       // Chebyshev: SpMVs per smoothing
  double chebyshev_ratio = 30.0;  // smooths the eigenvalues in [lambda_max / ratio, lambda_max]
  double jacobi_weight = 0.0;     // Jacobi smoother: 0 means 1 / rho(D^-1 A)
};

// The smoother's diagonal of rows [first, last): D_i^-1, or for Gauss-Seidel with the l1 term
// (D_i + diag(l1_i))^-1 with l1_i the row sums of |a| over the blocks outside the row's own
// block. That term makes hybrid Gauss-Seidel convergent for any SPD matrix and any partition
// (Baker et al. 2011, the l1 smoother).
template <int B>
void smoother_diagonal(Level<B>& level, bool l1, int first, int last) {
  using Vector = Eigen::Matrix<double, B, 1>;
  SmootherNumbers<B>& numbers = level.smoother;
  for (int i = first; i < last; ++i) {
    Eigen::Matrix<double, B, B> D = level.values[level.diagonal[i]];
    if (l1) {
      Vector sum = Vector::Zero();
      for (int k = level.A.row_start[i]; k < level.rows.inner_begin[i]; ++k)
        sum += level.values[k].cwiseAbs().rowwise().sum();
      for (int k = level.rows.inner_end[i]; k < level.A.row_start[i + 1]; ++k)
        sum += level.values[k].cwiseAbs().rowwise().sum();
      numbers.l1[i] = sum;
      D.diagonal() += sum;
    }
    numbers.inverse_diagonal[i] = D.inverse();
  }
}

// The largest eigenvalue of D^-1 A by power iteration, as the Rayleigh quotient
// x^T A x / x^T D x: from below. The first time from a fixed random start (deterministic),
// later from the last estimate's vector, which needs fewer iterations. D^-1 is the smoother's
// inverse diagonal unless that holds the l1 term. Uses the level's b and x as scratch; one
// thread (at a refresh only).
template <int B>
double spectral_radius(Level<B>& level, int iterations, bool plain_inverse) {
  Eigen::VectorXd &x = level.vectors.x, &y = level.vectors.b;
  x = level.smoother.power_start;
  double rho = 0.0;
  for (int it = 0; it < iterations; ++it) {
    multiply(level, x, y);
    double xDx = 0.0;
    for (int i = 0; i < level.nodes(); ++i) {
      const auto xi = x.template segment<B>(B * i);
      xDx += xi.dot(level.values[level.diagonal[i]] * xi);
    }
    rho = x.dot(y) / xDx;
    for (int i = 0; i < level.nodes(); ++i) {
      const auto yi = y.template segment<B>(B * i);
      if (plain_inverse)
        x.template segment<B>(B * i) = level.smoother.inverse_diagonal[i] * yi;
      else
        x.template segment<B>(B * i) = level.values[level.diagonal[i]].inverse() * yi;
    }
    x /= x.norm();
  }
  level.smoother.power_start = x;
  return rho;
}

// The weights of the polynomial smoothers, per step: d = alpha d + beta D^-1 r, x += d.
// Jacobi: alpha 0, beta w. Chebyshev on [lambda / ratio, lambda] (Saad, Iterative Methods,
// algorithm 12.1): beta_0 = 1 / theta, then rho_k = 1 / (2 sigma - rho_(k-1)),
// alpha_k = rho_k rho_(k-1), beta_k = 2 rho_k / delta.
template <int B>
void polynomial_weights(SmootherNumbers<B>& numbers, const SmootherSettings& settings) {
  auto& w = numbers.weights;
  const bool chebyshev = settings.smoother == Smoother::Chebyshev;
  const int steps = chebyshev ? settings.chebyshev_degree * settings.sweeps : settings.sweeps;
  w.assign(2 * steps, 0.0);
  if (!chebyshev) {
    for (int k = 0; k < steps; ++k) w[2 * k + 1] = numbers.jacobi_weight;
    return;
  }
  const double upper = numbers.lambda_max, lower = upper / settings.chebyshev_ratio;
  const double theta = 0.5 * (upper + lower), delta = 0.5 * (upper - lower);
  const double sigma = theta / delta;
  double rho = 1.0 / sigma;
  w[1] = 1.0 / theta;
  for (int k = 1; k < steps; ++k) {
    const double next = 1.0 / (2.0 * sigma - rho);
    w[2 * k] = next * rho;
    w[2 * k + 1] = 2.0 * next / delta;
    rho = next;
  }
}

// ---- the smoothers, on the rows [first, last) of one block --------------------------------

// x = (D + L)^-1 b inside the block from x = 0: hybrid Gauss-Seidel's first forward sweep.
// The blocks right of the diagonal and outside the block multiply zeros, so only the lower
// part inside the block is read, and no other block's rows: no wait for another thread.
template <int B>
void gauss_seidel_from_zero(const Level<B>& level, int first, int last, const Eigen::VectorXd& b,
                            Eigen::VectorXd& x) {
  for (int i = first; i < last; ++i) {
    const Eigen::Matrix<double, B, 1> r =
        b.template segment<B>(B * i) -
        row_product(level, x, level.rows.inner_begin[i], level.diagonal[i]);
    x.template segment<B>(B * i).noalias() = level.smoother.inverse_diagonal[i] * r;
  }
}

// out_i = in_i + D_i^-1 (b - A x)_i, forward or backward through the block, where x is out on
// the block's rows already swept and in everywhere else: Gauss-Seidel inside the block,
// Jacobi between blocks (other blocks are read only from in, which no thread writes during
// the sweep). The backward sweep is the adjoint of the forward one: the V-cycle stays
// symmetric.
template <int B>
void gauss_seidel(const Level<B>& level, int first, int last, const Eigen::VectorXd& b,
                  const Eigen::VectorXd& in, Eigen::VectorXd& out, bool forward) {
  const auto& A = level.A;
  const RowBlocks& rows = level.rows;
  for (int s = 0; s < last - first; ++s) {
    const int i = forward ? first + s : last - 1 - s;
    const int d = level.diagonal[i], end = A.row_start[i + 1];
    Eigen::Matrix<double, B, 1> sum;
    if (forward)
      sum = row_product(level, in, A.row_start[i], rows.inner_begin[i]) +
            row_product(level, out, rows.inner_begin[i], d) + row_product(level, in, d, end);
    else
      sum = row_product(level, in, A.row_start[i], d + 1) +
            row_product(level, out, d + 1, rows.inner_end[i]) +
            row_product(level, in, rows.inner_end[i], end);
    out.template segment<B>(B * i).noalias() =
        in.template segment<B>(B * i) +
        level.smoother.inverse_diagonal[i] * (b.template segment<B>(B * i) - sum);
  }
}

// D_i^-1 r as an expression: `beta * (D_i^-1 r)` then evaluates as Eigen rewrites a scalar
// times a product, (beta D_i^-1) r (the scalar-times-product evaluator, Eigen/src/Core/
// ProductEvaluators.h).
template <int B, class Rhs>
EIGEN_ALWAYS_INLINE auto times_inverse_diagonal(const Level<B>& level, int i, const Rhs& r) {
  return level.smoother.inverse_diagonal[i] * r;
}

// A polynomial smoother's step k: d = alpha d + beta D^-1 (b - A in), out = in + d; from
// zero (in null) d = beta D^-1 b, out = d. Reads in on every row, writes out and d on its own.
// For any level whose numbers answer row_product and times_inverse_diagonal (found by
// argument-dependent lookup) and hold their weights in level.smoother.weights. One loop in
// this form for every level: GCC fuses a multiply and an add where it sees them
// (-ffp-contract=fast, its default), so the loop's form is part of the rounding.
template <class L, class Vector>
void polynomial_step(L& level, int k, int first, int last, const Vector& b, const Vector* in,
                     Vector& out) {
  constexpr int B = L::block_size;
  const auto alpha = level.smoother.weights[2 * k], beta = level.smoother.weights[2 * k + 1];
  const auto& A = source_level(level).A;
  for (int i = first; i < last; ++i) {
    Eigen::Matrix<typename Vector::Scalar, B, 1> r = b.template segment<B>(B * i);
    if (in) r -= row_product(level, *in, A.row_start[i], A.row_start[i + 1]);
    auto d = level.vectors.direction.template segment<B>(B * i);
    if (k == 0 || !in)
      d.noalias() = beta * times_inverse_diagonal(level, i, r);
    else
      d = alpha * d + beta * times_inverse_diagonal(level, i, r);
    if (in)
      out.template segment<B>(B * i) = in->template segment<B>(B * i) + d;
    else
      out.template segment<B>(B * i) = d;
  }
}

// ---- what the V-cycle calls ---------------------------------------------------------------

// Smoothing steps per pre- or post-smoothing.
template <int B>
int smoothing_steps(const Level<B>& level) {
  const SmootherNumbers<B>& numbers = level.smoother;
  return numbers.gauss_seidel ? numbers.sweeps : static_cast<int>(numbers.weights.size()) / 2;
}

// Step k of a smoothing on rows [first, last): from zero when in is null; forward before the
// coarse correction, backward after (Gauss-Seidel; the polynomial steps are their own adjoint).
template <int B>
void smooth(Level<B>& level, int k, int first, int last, const Eigen::VectorXd& b,
            const Eigen::VectorXd* in, Eigen::VectorXd& out, bool forward) {
  if (!level.smoother.gauss_seidel)
    polynomial_step(level, k, first, last, b, in, out);
  else if (in)
    gauss_seidel(level, first, last, b, *in, out, forward);
  else
    gauss_seidel_from_zero(level, first, last, b, out);
}

// b - A x on row i.
template <class L, class Vector, int B = L::block_size>
EIGEN_ALWAYS_INLINE Eigen::Matrix<typename Vector::Scalar, B, 1> plain_residual(const L& level,
                                                                                int i,
                                                                                const Vector& b,
                                                                                const Vector& x) {
  const auto& A = source_level(level).A;
  return b.template segment<B>(B * i) - row_product(level, x, A.row_start[i], A.row_start[i + 1]);
}

// b - A x on rows [first, last) into the level's residual vector. After exactly one forward
// Gauss-Seidel sweep from zero, (D + diag(l1) + L_block) x = b row by row, so the residual is
// l1 x minus the product of the blocks right of the diagonal and outside the block: the
// sweep and the residual together read the matrix once.
template <int B>
void residual(Level<B>& level, int first, int last, const Eigen::VectorXd& b,
              const Eigen::VectorXd& x) {
  const auto& A = level.A;
  const bool after_one_sweep = level.smoother.gauss_seidel && level.smoother.sweeps == 1;
  for (int i = first; i < last; ++i) {
    auto r = level.vectors.residual.template segment<B>(B * i);
    if (after_one_sweep)
      r = level.smoother.l1[i].cwiseProduct(x.template segment<B>(B * i)) -
          row_product(level, x, A.row_start[i], level.rows.inner_begin[i]) -
          row_product(level, x, level.diagonal[i] + 1, A.row_start[i + 1]);
    else
      r = plain_residual(level, i, b, x);
  }
}

// A level on the same hierarchy with other numbers and a polynomial smoother derives from
// PolynomialLevel: a base class's namespace is searched by argument-dependent lookup, so the
// V-cycle then finds these three for it (the same smoothing steps, the polynomial steps and the
// plain residual, on its own row_product and times_inverse_diagonal), and no other level does.
struct PolynomialLevel {};
template <class L>
using IfPolynomialLevel = std::enable_if_t<std::is_base_of_v<PolynomialLevel, L>, int>;

template <class L, IfPolynomialLevel<L> = 0>
int smoothing_steps(const L& level) {
  return static_cast<int>(level.smoother.weights.size()) / 2;
}
template <class L, class Vector, IfPolynomialLevel<L> = 0>
void smooth(L& level, int k, int first, int last, const Vector& b, const Vector* in, Vector& out,
            bool /*forward*/) {
  polynomial_step(level, k, first, last, b, in, out);
}
template <class L, class Vector, IfPolynomialLevel<L> = 0>
void residual(L& level, int first, int last, const Vector& b, const Vector& x) {
  constexpr int B = L::block_size;
  for (int i = first; i < last; ++i)
    level.vectors.residual.template segment<B>(B * i) = plain_residual(level, i, b, x);
}

}  // namespace fem::ch10
