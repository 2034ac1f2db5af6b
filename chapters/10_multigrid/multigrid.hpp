// Chapter 10: smoothed-aggregation algebraic multigrid (Vanek, Mandel & Brezina 1996) on 3x3
// block matrices, as the preconditioner of the PPCG solve (Tamstorf, Jones & McCormick 2015,
// the poster's reference for its constraint method).
//
// The split that makes it cheap enough to run every step: everything that depends only on
// the mesh (aggregates, the tentative prolongator from the rigid-body modes, the patterns of
// the smoothed prolongator and of every Galerkin product P^T A P, and tables that say where
// each block product lands) is built once, in the constructor. prepare(A) then recomputes
// only numbers on those fixed patterns, and apply(r, z) is one V-cycle. Neither allocates.
//
// The multigrid knows nothing of the stepper: it reads the fine matrix as block compressed
// rows (row_start, column, blocks), the layout of chapter 07's BlockSparseMatrix.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "common/scene.hpp"

namespace fem::ch10 {

// The hierarchy's matrices are chapter 07's block compressed rows, with 6x6 blocks on the
// aggregates and 3x6 blocks in the prolongators.
using ch07::BlockCsr;

// Every coarse unknown is one aggregate of nodes carrying 6 near-null-space modes.
constexpr int kModes = 6;

struct MultigridSettings {
  enum class Smoother { GaussSeidel, Jacobi };
  // Modes per aggregate: 6 (3 translations, 3 rotations) or 3 (translations only). The
  // coarse blocks stay 6 x 6; unused modes become identity rows, as constrained dofs do.
  int modes = kModes;
  Smoother smoother = Smoother::GaussSeidel;
  int sweeps = 1;             // pre- and post-smoothing sweeps per level
  double jacobi_weight = 0.0; // damped block-Jacobi smoother: 0 means 1 / rho(D^-1 A)
  bool smooth_prolongator = true;   // P = (I - w D^-1 A) T; false: P = T (plain aggregation)
  bool update_prolongator = false;  // recompute P every step (default: the first step's)
  int power_iterations = 10;        // estimate of rho(D^-1 A) for the prolongator smoother
  // Coarse matrices recomputed every k-th prepare (1: every step). In between, only the finest
  // level follows the new matrix; the V-cycle stays SPD, only its quality can suffer.
  int coarse_refresh = 1;
  int max_coarse_dofs = 200;        // the dense Cholesky's size limit
  int max_levels = 8;
};

// One level of the hierarchy; B is the block size of its unknowns (3 on the mesh, 6 on the
// aggregates). The finest level's matrix values belong to the caller.
template <int B>
struct Level {
  using Block = Eigen::Matrix<double, B, B>;
  using Transfer = Eigen::Matrix<double, B, kModes>;

  BlockCsr<B, B> A;           // pattern; values in A.blocks except on the finest level
  const Block* values = nullptr;
  std::vector<int> diagonal;  // per node: index of block (i, i)
  std::vector<Block> inverse_diagonal;
  // Per node of a coarse level: 1 on the modes its aggregate lacks (constrained or
  // degenerate), where the Galerkin matrix is zero and gets the identity, as I - S does.
  std::vector<Eigen::Matrix<double, B, 1>> unused;

  bool coarsest = true;  // no transfer below: solved by the dense Cholesky
  std::vector<std::vector<int>> graph;  // the neighbours that aggregation considers
  std::vector<int> aggregate;           // per node: its aggregate (coarse node)
  std::vector<Transfer> tentative;     // per node: its block of T
  BlockCsr<B, kModes> P;               // smoothed prolongator, pattern of A T
  std::vector<int> tentative_block;    // per node: index of (i, aggregate[i]) in P
  std::vector<int> at_target;          // per block k of A: where A_k T_j lands in P
  BlockCsr<B, kModes> AP;              // the pattern of A P; blocks: one row's buffer
  std::vector<int> ap_target;          // per product A_k P_m, in loop order: its place in the row
  // A_c is symmetric: only its blocks (c, d) with d >= c are computed. Per block m of P (in
  // row i, column c), the first block of row i of A P with a column >= c; the targets of
  // those products in loop order; and the (lower, upper) pairs copied by transposition.
  std::vector<int> galerkin_first;
  std::vector<int> galerkin_target;
  std::vector<std::array<int, 2>> galerkin_mirror;
  double omega = 0.0;                  // prolongator smoothing weight 4 / (3 rho)
  double jacobi_weight = 0.0;          // smoother weight (Jacobi smoother)

  Eigen::VectorXd b, x, work, start;  // right-hand side, solution, residual, power start
  Eigen::MatrixXd dense;              // coarsest level: the matrix and its Cholesky factor
  Eigen::LLT<Eigen::MatrixXd> cholesky;

  int nodes() const { return A.block_rows(); }
  int dofs() const { return B * nodes(); }
};

class Multigrid {
 public:
  // Set-up from the fine pattern (block compressed rows, the diagonal included), the rest
  // positions X (3N) for the rigid-body modes and the constraints (the filter S_i of each
  // constrained node removes its constrained directions from the near-null space).
  Multigrid(const std::vector<int>& row_start, const std::vector<int>& column,
            const Eigen::VectorXd& rest_positions, const std::vector<NodeConstraint>& constraints,
            const MultigridSettings& settings = {});

  // The numbers of this step's filtered matrix (same pattern as at set-up): smoothed
  // prolongators, coarse matrices, smoothers, Cholesky. The blocks must stay alive and
  // unchanged until the last apply().
  void prepare(const std::vector<Eigen::Matrix3d>& fine_blocks);
  // z = M r, one V-cycle from a zero guess: symmetric, positive definite.
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z);

  const MultigridSettings& settings() const { return settings_; }
  int levels() const { return 1 + static_cast<int>(coarse_.size()); }
  int level_dofs(int level) const;
  long long level_blocks(int level) const;  // stored blocks of the level's matrix
  long long prolongator_blocks(int level) const;  // blocks of P from level to level + 1
  // For tests and reports (allocate): level matrices, prolongators from level to level + 1,
  // and the identity diagonal added on the unused modes of level (level >= 1).
  Eigen::SparseMatrix<double> level_matrix(int level) const;
  Eigen::SparseMatrix<double> prolongator(int level) const;
  Eigen::VectorXd unused_modes(int level) const;

 private:
  template <int B>
  void prepare_level(Level<B>& level, std::size_t next);
  template <int B>
  void cycle(Level<B>& level, std::size_t next, const Eigen::VectorXd& b, Eigen::VectorXd& x);

  MultigridSettings settings_;
  Level<3> fine_;
  std::vector<Level<kModes>> coarse_;
  bool prolongators_ready_ = false;
  long long prepares_ = 0;
};

}  // namespace fem::ch10
