// Chapter 09: every core, deterministically. The same step as before, on all the threads
// OpenMP is given (OMP_NUM_THREADS or --threads): the element pass without races or
// atomics, the block SpMV over rows, the PCG's vector operations fused so that an
// iteration waits at three barriers, and every sum over the mesh taken over a FIXED
// partition in a fixed order, so that the state after any number of steps is the same to
// the last bit for any thread count.
#pragma once

#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <vector>

#include "common/model.hpp"
#include "common/stepper.hpp"

namespace fem::ch09 {

// Block compressed-row storage: row i (node i) holds blocks row_start[i] .. row_start[i+1]-1,
// block k is blocks[k] at block column column[k], columns sorted within a row.
struct BlockSparseMatrix {
  std::vector<int> row_start;
  std::vector<int> column;
  std::vector<Eigen::Matrix3d> blocks;

  BlockSparseMatrix() = default;
  // The pattern of a symmetric node adjacency (each row sorted, the node itself included).
  explicit BlockSparseMatrix(const std::vector<std::vector<int>>& adjacency);

  int block_rows() const { return static_cast<int>(row_start.size()) - 1; }
  // Index of block (i, j) in blocks, found by a binary search: for set-up only.
  int find(int i, int j) const;
  // y_i = sum_j A_ij x_j for the rows [first, last): each y_i written once, by one thread.
  void multiply_rows(const Eigen::VectorXd& x, Eigen::VectorXd& y, int first, int last) const;
  // y = A x on the calling thread (tests, set-up).
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  // Conversion for tests and comparisons (allocates).
  Eigen::SparseMatrix<double> to_sparse() const;
};

// The fixed partition of the node rows that every parallel loop and every sum uses: the
// chunks hold about the same number of blocks, and they do not depend on the thread
// count. Threads take whole chunks (a static schedule); a sum over the mesh is the sum of
// per-chunk sums, added in chunk order: the same additions in the same order for any
// number of threads.
struct RowChunks {
  static constexpr int kCount = 64;
  std::vector<int> start;  // chunk c holds rows start[c] .. start[c+1]-1

  RowChunks() = default;
  explicit RowChunks(const BlockSparseMatrix& pattern);
  int count() const { return static_cast<int>(start.size()) - 1; }
};

struct PcgResult {
  int iterations = 0;
  double relative_residual = 0.0;  // ||b - A y|| / ||b||, as Eigen's error()
  bool converged = false;
};

// Block-Jacobi preconditioned CG on the filtered block system, with the stopping rule and
// PPCG filter of the chapters before, in one parallel region. The work vectors are sized
// on the first solve and reused.
class ParallelPcg {
 public:
  ParallelPcg() = default;
  ParallelPcg(const BlockSparseMatrix& pattern, const std::vector<int>& diagonal_block,
              const std::vector<NodeConstraint>& constraints);
  // y holds the initial guess on entry and the solution on exit.
  PcgResult solve(const BlockSparseMatrix& A, const Eigen::VectorXd& b,
                  const SolverSettings& settings, Eigen::VectorXd& y);
  const RowChunks& chunks() const { return chunks_; }

 private:
  RowChunks chunks_;
  std::vector<int> diagonal_block_;
  // The constraints sorted by node; chunk c's are chunk_constraints_[chunk_constraint_start_[c]..].
  std::vector<NodeConstraint> chunk_constraints_;
  std::vector<int> chunk_constraint_start_;
  std::vector<Eigen::Matrix3d> inverse_diagonal_;    // block Jacobi: (A_ii)^-1
  Eigen::VectorXd r_, s_, p_, q_;
  // Per-chunk partial sums, one array per reduction so that no array is rewritten while
  // a slower thread may still be adding it up.
  std::vector<double> partial_bb_, partial_pq_, partial_rr_, partial_rs_;
};

// How the element pass avoids two threads adding into the same node at once.
enum class ElementParallelism {
  // Each element computes its force and blocks and a node's sums are gathered afterwards,
  // by the thread that owns the node's row, in element order.
  gather,
  // The elements are coloured so that no two of a colour share a node; one colour at a
  // time, the threads scatter their elements' contributions as the serial code does.
  colouring,
};

class ThreadsStepper final : public Stepper {
 public:
  ThreadsStepper(const Scene& scene, const SolverSettings& settings,
                 ElementParallelism element_parallelism = ElementParallelism::colouring);
  void step(State& state) override;
  const StepProfile& profile() const override { return profile_; }

  // The last step's filtered system S A S^T + I - S and right-hand side S (b - A z).
  const BlockSparseMatrix& system_matrix() const { return A_; }
  const Eigen::VectorXd& system_rhs() const { return filtered_b_; }
  const BlockSparseMatrix& dfdx() const { return dfdx_; }
  const Eigen::VectorXd& forces() const { return f_; }
  int colours() const { return static_cast<int>(colour_start_.size()) - 1; }

 private:
  void compute_forces(const State& state);
  void build_dfdx();
  void compose_system(const State& state);
  void apply_constraints(const State& state);
  void solve();

  Scene scene_;
  Model model_;
  SolverSettings settings_;
  ElementParallelism element_parallelism_;
  StepProfile profile_;
  bool warned_not_converged_ = false;

  std::vector<Eigen::Matrix3d> rotations_;           // R_e of the polar decomposition, per element
  std::vector<Vector12d> element_forces_;            // f_e, per element (gather only)
  Eigen::VectorXd f_;                                // elastic forces + gravity
  BlockSparseMatrix dfdx_;                           // pattern of the mesh connectivity, built once
  std::vector<std::array<int, 16>> element_blocks_;  // per element: block of (a, b)
  RowChunks chunks_;
  // Gather: per node, the (element, corner) pairs 4 e + a that touch it; per block, the
  // (element, block) pairs 16 e + 4 a + b that add into it. Both in element order.
  std::vector<int> node_corner_start_, node_corners_;
  std::vector<int> block_term_start_, block_terms_;
  // Colouring: groups of kGroup consecutive elements sorted by colour; colour c holds the
  // groups colour_order_[colour_start_[c]] .. colour_order_[colour_start_[c+1]-1].
  static constexpr int kGroup = 16;
  std::vector<int> colour_order_, colour_start_;
  int group_first(int g) const { return g * kGroup; }
  int group_last(int g) const {
    return std::min(static_cast<int>(model_.tets.size()), (g + 1) * kGroup);
  }
  BlockSparseMatrix A_;               // M - h df/dv - h^2 df/dx, the pattern of dfdx_
  std::vector<int> diagonal_block_;   // per node: index of block (i, i)
  std::vector<int> transpose_block_;  // per block (i, j): index of block (j, i)
  Eigen::VectorXd b_;                 // h (f + h df/dx v)
  Eigen::VectorXd z_;                 // prescribed velocity change of constrained dofs
  Eigen::VectorXd filtered_b_;        // S (b - A z)
  Eigen::VectorXd dv_;
  ParallelPcg pcg_;
  Eigen::VectorXd y_;  // the unknown of the filtered system, dv = y + z: also the warm start
};

}  // namespace fem::ch09
