// Chapter 12's preconditioner: chapter 10's V-cycle on half the bytes. Once the hierarchy is
// lagged and parallel, a V-cycle is bound by memory traffic: it streams every level's blocks,
// the prolongators and the smoothers' inverse diagonals, several times per cycle. The
// preconditioner only has to be good, not exact, so those numbers are stored in float:
// half the bytes to stream. The outer PCG (chapter 09's), its vectors, the system matrix and
// the stopping rule stay in double, so the solve converges to the same tolerance: M changes
// a little, and PCG only needs M symmetric positive definite (AMGCL's mixed precision,
// Demidov 2019; Tamstorf et al. 2015 precondition in the same spirit).
//
// The hierarchy itself is still chapter 10's Multigrid: it is set up and factorized in double
// (aggregates, Galerkin products, Chebyshev bounds, Cholesky), and this class reads its
// numbers into float after each factorize(): the finest level every step, the coarse levels
// after a refresh only. The V-cycle is chapter 10's (v_cycle.hpp), run on float levels in
// `Real` arithmetic: Real = float (everything in single precision) or Real = double (float
// loads widened in registers: the bytes of float, the rounding of double), the two the lesson
// measures. Only its kernels are new (reduced_v_cycle.cpp).
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/10_multigrid/multigrid.hpp"

namespace fem::ch12 {

using ch10::kModes;

// One level of the hierarchy with the numbers the V-cycle reads in float; the pattern, the
// row blocks, the refresh rule and the coarsest Cholesky factor stay the source level's. A
// PolynomialLevel: chapter 10's polynomial smoothing steps and residual run on its products.
template <class Real, int B>
struct ReducedLevel : ch10::PolynomialLevel {
  static constexpr int block_size = B;
  const ch10::Level<B>* source = nullptr;
  std::vector<Eigen::Matrix<float, B, B>> blocks;  // the level's matrix
  std::vector<Eigen::Matrix<float, B, kModes>> P;  // the prolongator's blocks
  std::vector<Eigen::Matrix<float, kModes, B>> R;  // the restriction's, in R's order
  struct {
    std::vector<Eigen::Matrix<float, B, B>> inverse_diagonal;  // D^-1
    std::vector<Real> weights;
  } smoother;
  ch10::WorkVectors<Real> vectors;
  Eigen::VectorXd dense;  // coarsest level: the right-hand side of the double Cholesky
};

// The pattern, row blocks and transfers of chapter 10's V-cycle and smoothers: the source's.
template <class Real, int B>
const ch10::Level<B>& source_level(const ReducedLevel<Real, B>& level) {
  return *level.source;
}

enum class Arithmetic { single, double_on_float };

template <class Real>
class ReducedVCycle {
 public:
  using Vector = Eigen::Matrix<Real, Eigen::Dynamic, 1>;

  // The hierarchy must outlive this object; its settings must use a polynomial smoother
  // (Chebyshev or Jacobi: chapter 10's default), which this V-cycle runs.
  explicit ReducedVCycle(ch10::Multigrid& multigrid);

  // Chapter 10's factorize in double, then its new numbers into float. By every thread.
  void prepare(const ch07::BlockSparseMatrix& A);
  // s = M r, one V-cycle in Real arithmetic on the float numbers. By every thread.
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& s);

  // The bytes one V-cycle's numbers occupy: blocks, prolongators (P and R) and inverse
  // diagonals of every level; chapter 10's in double are twice as many.
  long long number_bytes() const;

  // The float levels, for a cycle run on them in another order of loops.
  ReducedLevel<Real, 3>& fine_level() { return fine_; }
  std::vector<ReducedLevel<Real, kModes>>& coarse_levels() { return coarse_; }

 private:
  template <int B>
  void convert(ReducedLevel<Real, B>& level, bool refreshed, bool collective);

  ch10::Multigrid& multigrid_;
  ReducedLevel<Real, 3> fine_;
  std::vector<ReducedLevel<Real, kModes>> coarse_;
  Vector r_, s_;  // the PCG's residual and its preconditioned residual in Real
  // The coarse levels, prolongators and weights read once. Every thread reads it on entry to
  // prepare and one thread sets it after: between them stand the conversion's barriers, except
  // in a one-level hierarchy, which has nothing to convert; atomic, so that case is no data race.
  std::atomic<bool> converted_{false};
};

// The float V-cycle's entry and exit on the rows [first, last) of 3-vectors: r into float, or
// s back into double (ReducedVCycle::apply, chapter 14's LaneVCycle::apply, and the roofline's
// kernel alone).
template <class To, class From>
void convert_rows(const From& from, To& to, int first, int last) {
  const int f = 3 * first, size = 3 * (last - first);
  to.segment(f, size) = from.segment(f, size).template cast<typename To::Scalar>();
}

extern template class ReducedVCycle<float>;
extern template class ReducedVCycle<double>;

}  // namespace fem::ch12
