// Chapter 09's building block: the PCG on every core, deterministically. The rows are cut
// into a FIXED set of chunks (RowChunks); every parallel loop over rows shares out those
// chunks, and every sum over the mesh is a sum of per-chunk sums added in chunk order, never
// an OpenMP reduction (whose order of combination OpenMP leaves unspecified). So the solve
// gives the same bits for any thread count. The product and the preconditioner are parts
// (chapter 08's faces, contract.hpp): any that keep the same rules.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/08_element_kernels/contract.hpp"
#include "common/stepper.hpp"

namespace fem::ch09 {

using ch07::BlockSparseMatrix;

// The fixed partition of the node rows that every parallel loop over rows and every sum
// uses: up to 64 chunks of about the same number of blocks, whatever the thread count.
// Threads take whole chunks (a static schedule); a sum over the mesh is the sum of per-chunk
// sums, added in chunk order: the same additions in the same order for any thread count.
struct RowChunks {
  static constexpr int kMaxCount = 64, kMinRows = 32;
  std::vector<int> start;  // chunk c holds rows start[c] .. start[c+1]-1

  RowChunks() = default;
  explicit RowChunks(const BlockSparseMatrix& pattern);
  int count() const { return static_cast<int>(start.size()) - 1; }
  int rows(int c) const { return start[c + 1] - start[c]; }
  // The scalar entries of chunk c in a vector of 3 dofs per node: first and size.
  int first_dof(int c) const { return 3 * start[c]; }
  int dofs(int c) const { return 3 * rows(c); }
};

// The sum of per-chunk partial sums, in chunk order. Every thread adds them up itself after
// the barrier (64 additions): the same value on every thread, and no extra barrier to hand a
// result from one thread to the others.
double sum_in_order(const std::vector<double>& partial);

// The constraints sorted by node into `sorted`, and where each part's begin there: part p (its
// rows start[p] .. start[p + 1] - 1) holds sorted[first[p]] .. sorted[first[p + 1] - 1].
void constraints_by_part(const std::vector<NodeConstraint>& constraints,
                         const std::vector<int>& start, std::vector<NodeConstraint>& sorted,
                         std::vector<int>& first);

// The constraints of rows [first, last) among `sorted` (constraints_by_part), as a filter.
struct ChunkFilter {
  const NodeConstraint* begin = nullptr;
  const NodeConstraint* end = nullptr;
  // v_i <- S_i v_i on the constrained nodes: the PPCG projection.
  void operator()(Eigen::VectorXd& v) const {
    for (const NodeConstraint* c = begin; c != end; ++c)
      v.segment<3>(3 * c->node) = c->filter * v.segment<3>(3 * c->node);
  }
};

// The PCG's kernels on the block rows [first, last) of one chunk, each returning the chunk's
// part of the sum it ends with. ParallelPcg's loops call them, and so does the roofline's
// kernels alone (work.cpp): what it times is what the solve runs.
//   q = A p; p . q
double pcg_product(const ch08::ProductPart& A, const Eigen::VectorXd& p, Eigen::VectorXd& q,
                   int first, int last);
//   y += step p, r -= step q, r filtered; r . r
double pcg_update(double step, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                  Eigen::VectorXd& y, Eigen::VectorXd& r, const ChunkFilter& filter, int first,
                  int last);
//   p = s + beta p
void pcg_next_direction(double beta, const Eigen::VectorXd& s, Eigen::VectorXd& p, int first,
                        int last);

// Preconditioned CG on the filtered block system, with the same stopping rule and PPCG filter
// as chapter 06, in one parallel region. Set up once per pattern and set of constraints; the
// work vectors are sized on the first solve and reused.
class ParallelPcg {
 public:
  ParallelPcg() = default;
  ParallelPcg(const BlockSparseMatrix& pattern, const std::vector<NodeConstraint>& constraints);
  // The filter's constraints from the next solve on (a grab, a release, a floor's contacts).
  void set_constraints(const std::vector<NodeConstraint>& constraints);
  // y holds the initial guess on entry and the solution on exit; A is the system the product
  // and the preconditioner prepare from.
  SolveStats solve(const BlockSparseMatrix& A, ch08::ProductPart& product,
                   ch08::PreconditionerPart& M, const Eigen::VectorXd& b,
                   const SolverSettings& settings, Eigen::VectorXd& y);
  const RowChunks& chunks() const { return chunks_; }

 private:
  using Product = ch08::ProductPart;
  using Preconditioner = ch08::PreconditionerPart;
  // The steps of one solve, each called by every thread and each one `omp for` over the
  // chunks (so one barrier): they return the sum over the mesh, the same on every thread.
  SolveStats iterate(const Product& A, Preconditioner& M, const Eigen::VectorXd& b,
                     double rhs_norm2, const SolverSettings& settings, Eigen::VectorXd& y);
  double filter_guess(const Eigen::VectorXd& b, Eigen::VectorXd& y);  // S y; ||b||^2
  double residual(const Product& A, const Preconditioner& M, const Eigen::VectorXd& b,
                  const Eigen::VectorXd& y);                   // r = S (b - A y); ||r||^2
  double precondition(Preconditioner& M, Eigen::VectorXd& s);  // s = S M r; r . s
  double product(const Product& A);                            // q = A p; p . q
  double update(const Preconditioner& M, double step, Eigen::VectorXd& y);  // y, r; ||r||^2
  void next_direction(double beta);                                         // p = s + beta p
  // Chunk c's share of the block-diagonal M: s = S M r on its rows, and its part of r . s.
  void precondition_chunk(const Preconditioner& M, int c, Eigen::VectorXd& s);
  // The PPCG projection on the constrained nodes of chunk c.
  ChunkFilter filter(int c) const {
    return {constraints_.data() + constraint_start_[c],
            constraints_.data() + constraint_start_[c + 1]};
  }

  RowChunks chunks_;
  // The constraints sorted by node: chunk c's are constraints_[constraint_start_[c] ..].
  std::vector<NodeConstraint> constraints_;
  std::vector<int> constraint_start_;
  Eigen::VectorXd r_, s_, p_, q_;
  // Per-chunk partial sums, one array per reduction, so that no array is written again
  // while a slower thread may still be adding it up.
  std::vector<double> partial_bb_, partial_pq_, partial_rr_, partial_rs_;
};

}  // namespace fem::ch09
