// Chapter 10: smoothed-aggregation algebraic multigrid (Vanek, Mandel & Brezina 1996) on 3x3
// block matrices, as the preconditioner of the PPCG solve (Tamstorf, Jones & McCormick 2015,
// the poster's reference for its constraint method).
//
// The split that makes it cheap enough to run every step: everything that depends only on
// the mesh (aggregates, the tentative prolongator from the rigid-body modes, the patterns of
// the smoothed prolongator and of every Galerkin product P^T A P, tables that say where each
// block product lands, and a FIXED partition of every level's rows into blocks) is built
// once, in the constructor. prepare(A) then recomputes only numbers on those fixed patterns,
// and apply(r, z) is one V-cycle. Neither allocates.
//
// Both run on every thread of the caller's OpenMP team: every loop is shared out like an
// orphaned `omp for` (chapter 09's StaticShare) over the level's fixed row blocks, every sum runs
// in a fixed order, so the result is the same to the last bit for any thread count. Called outside
// a parallel region, they run on the calling thread alone.
//
// The coarse matrices live across steps: prepare() recomputes them every k-th call, or
// earlier when the V-cycles per solve grow (the refresh rule); the finest level always uses
// the matrix it is given, so the V-cycle stays symmetric positive definite.
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
  // GaussSeidel: l1-hybrid block Gauss-Seidel (Baker, Falgout, Kolev & Yang 2011): Gauss-Seidel
  // inside each row block, Jacobi between blocks, the diagonal grown by the l1 norm of the
  // couplings to other blocks; forward before the coarse correction, backward after.
  // Chebyshev: a Chebyshev polynomial in D^-1 A (Adams, Brezina, Hu & Tuminaro 2003).
  // Jacobi: damped block Jacobi. All three are parallel and symmetric in the V-cycle.
  enum class Smoother { GaussSeidel, Chebyshev, Jacobi };
  // Modes per aggregate: 6 (3 translations, 3 rotations) or 3 (translations only). The
  // coarse blocks stay 6 x 6; unused modes become identity rows, as constrained dofs do.
  int modes = kModes;
  Smoother smoother = Smoother::Chebyshev;
  int sweeps = 1;  // pre- and post-smoothing sweeps per level
  bool l1 = true;  // Gauss-Seidel: the l1 term (false: plain hybrid Gauss-Seidel)
  // The fixed row blocks of every level: at most max_blocks blocks of at least block_rows
  // rows of 3x3 blocks (a quarter as many rows of 6x6), equal in stored blocks. They are the
  // Gauss-Seidel smoother's blocks and the unit of work that threads share out; a function of
  // the mesh, never of the thread count. 1 block: sequential Gauss-Seidel on one thread.
  int max_blocks = 64;
  int block_rows = 32;
  // A level with fewer rows than this runs (with all levels below it) on one thread: there a
  // barrier costs more than the work it shares out.
  int serial_rows = 0;
  int chebyshev_degree = 3;         // Chebyshev: SpMVs per smoothing
  double chebyshev_ratio = 30.0;    // smooths the eigenvalues in [lambda_max / ratio, lambda_max]
  double jacobi_weight = 0.0;       // Jacobi smoother: 0 means 1 / rho(D^-1 A)
  bool smooth_prolongator = true;   // P = (I - w D^-1 A) T; false: P = T (plain aggregation)
  bool update_prolongator = false;  // smooth P at every refresh (default: on the first)
  int power_iterations = 30;  // the first estimate of rho(D^-1 A) (see README: 10 was too few)
  // Sweeps of symmetric Gauss-Seidel on A B = 0 that improve the rigid-body modes B on the
  // first matrix before T is built (PyAMG's improve_candidates); 0: the modes as they are.
  int improve_candidates = 4;
  // The refresh rule for the coarse matrices: recomputed every coarse_refresh-th prepare,
  // and earlier when the last solve took more than refresh_growth times the V-cycles of the
  // solve right after the last refresh (0: never earlier). 1: every step.
  int coarse_refresh = 20;
  double refresh_growth = 1.25;
  int max_coarse_dofs = 200;  // the dense Cholesky's size limit
  // Not the hierarchy's but the stepper's: the PCG's guess, the polynomial through the last
  // extrapolation + 1 solutions one step ahead (0: the last solution, chapter 09's warm start;
  // 1: 2 y_n - y_(n-1); 2: 3 y_n - 3 y_(n-1) + y_(n-2)).
  int extrapolation = 2;
  int max_levels = 8;
};

// One level of the hierarchy; B is the block size of its unknowns (3 on the mesh, 6 on the
// aggregates). The finest level's matrix values belong to the caller.
template <int B>
struct Level {
  using Block = Eigen::Matrix<double, B, B>;
  using Vector = Eigen::Matrix<double, B, 1>;
  using Transfer = Eigen::Matrix<double, B, kModes>;

  BlockCsr<B, B> A;  // pattern; values in A.blocks except on the finest level
  const Block* values = nullptr;
  std::vector<int> diagonal;   // per node: index of block (i, i)
  std::vector<int> transpose;  // per block (i, j): index of block (j, i) (coarse levels)
  // The fixed row blocks: block p holds rows part[p] .. part[p+1]-1. Per row, its blocks
  // with a column inside the row's own block: inner_begin[i] .. inner_end[i]-1.
  std::vector<int> part, inner_begin, inner_end;
  bool serial = false;  // run on one thread (serial_rows)
  // The smoother's diagonal inverse per node: (D_i + diag(l1_i))^-1 for Gauss-Seidel, D_i^-1
  // otherwise; l1_i the row sums of |a| over the couplings to other blocks.
  std::vector<Block> inverse_diagonal;
  std::vector<Vector> l1;
  // Per node of a coarse level: 1 on the modes its aggregate lacks (constrained or
  // degenerate), where the Galerkin matrix is zero and gets the identity, as I - S does.
  std::vector<Eigen::Matrix<double, B, 1>> unused;

  bool coarsest = true;                 // no transfer below: solved by the dense Cholesky
  std::vector<std::vector<int>> graph;  // the neighbours that aggregation considers
  std::vector<int> aggregate;           // per node: its aggregate (coarse node)
  std::vector<Transfer> modes;          // per node: its near-null-space modes (before T)
  std::vector<Transfer> tentative;      // per node: its block of T
  BlockCsr<B, kModes> P;                // smoothed prolongator, pattern of A T
  std::vector<int> tentative_block;     // per node: index of (i, aggregate[i]) in P
  std::vector<int> at_target;           // per block k of A: where A_k T_j lands in P
  // P^T by rows of the next level: its entries e are blocks pt_block[e] of P (the restriction
  // and the Galerkin product, by the owner of each coarse row).
  BlockCsr<kModes, B> PT;
  std::vector<int> pt_block;
  std::vector<Eigen::Matrix<double, kModes, B>> p_transposed;  // per block m of P: P_m^T
  // A P on its pattern (its values transposed in apt), every row: row i is computed by the
  // owner of fine row i; per product A_k P_m (row by row, in loop order), where it lands.
  BlockCsr<B, kModes> AP;
  std::vector<Eigen::Matrix<double, kModes, B>> apt;
  std::vector<int> ap_target;
  std::vector<int> ap_first;  // per row: its first product's index into ap_target
  // A_c is symmetric: only its blocks (c, d) with d >= c are computed, by the owner of row c.
  // Per block m of P (in row i, column c), the first block of row i of A P with a column >= c;
  // per coarse row c, its targets start at galerkin_start[c], in loop order.
  std::vector<int> galerkin_first;
  std::vector<int> galerkin_target, galerkin_start;
  double omega = 0.0;             // prolongator smoothing weight 4 / (3 rho)
  double jacobi_weight = 0.0;     // smoother weight (Jacobi smoother)
  double lambda_max = 0.0;        // rho(D^-1 A) (Chebyshev smoother)
  std::vector<double> chebyshev;  // per Chebyshev step: the weights of d and of D^-1 r

  // Right-hand side, solution, the ping-pong partner of x, residual, Chebyshev direction,
  // power iteration start.
  Eigen::VectorXd b, x, y, work, direction, start;
  Eigen::MatrixXd dense;  // coarsest level: the matrix and its Cholesky factor
  Eigen::LLT<Eigen::MatrixXd> cholesky;

  int nodes() const { return A.block_rows(); }
  int dofs() const { return B * nodes(); }
  int parts() const { return static_cast<int>(part.size()) - 1; }
};

class Multigrid {
 public:
  // Set-up from the fine pattern (block compressed rows, the diagonal included), the rest
  // positions X (3N) for the rigid-body modes and the constraints (the filter S_i of each
  // constrained node removes its constrained directions from the near-null space).
  Multigrid(const std::vector<int>& row_start, const std::vector<int>& column,
            const Eigen::VectorXd& rest_positions, const std::vector<NodeConstraint>& constraints,
            const MultigridSettings& settings = {});

  // The numbers of this step's filtered matrix (same pattern as at set-up): the smoothers
  // of the finest level; at a refresh also the coarse matrices, their smoothers, the
  // Cholesky factor (and the prolongators the first time). The blocks must stay alive and
  // unchanged until the last apply(). Called by every thread of a team, or outside one.
  void prepare(const std::vector<Eigen::Matrix3d>& fine_blocks);
  // z = M r, one V-cycle from a zero guess: symmetric, positive definite. Called by every
  // thread of a team (r complete before the call), or outside one.
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z);

  const MultigridSettings& settings() const { return settings_; }
  // The levels as prepare() left them: chapter 12 reads their numbers into float.
  const Level<3>& fine_level() const { return fine_; }
  const Level<kModes>& coarse_level(int level) const { return coarse_.at(level - 1); }
  // A V-cycle run on these levels outside apply() (chapter 12's, in float) still counts for
  // the refresh rule. Called by every thread of a team, or outside one.
  void count_cycle();
  int levels() const { return 1 + static_cast<int>(coarse_.size()); }
  int level_dofs(int level) const;
  long long level_blocks(int level) const;        // stored blocks of the level's matrix
  long long prolongator_blocks(int level) const;  // blocks of P from level to level + 1
  int level_parts(int level) const;               // the level's fixed row blocks
  // Refreshes of the coarse matrices so far, and whether the last prepare() was one.
  long long refreshes() const { return refreshes_; }
  bool refreshed() const { return refreshed_; }
  // For the lesson's costs per level: prepare()'s own work on one level (as at a refresh, or
  // as between refreshes), and one V-cycle from `level` down on the level's own b. Same
  // calling rules as prepare() and apply(); after a first prepare().
  void prepare_level_only(int level, bool refresh);
  void cycle_from(int level);
  // For tests and reports (allocate): level matrices, prolongators from level to level + 1,
  // and the identity diagonal added on the unused modes of level (level >= 1).
  Eigen::SparseMatrix<double> level_matrix(int level) const;
  Eigen::SparseMatrix<double> prolongator(int level) const;
  Eigen::VectorXd unused_modes(int level) const;

 private:
  template <int B>
  void prepare_level(Level<B>& level, std::size_t next, bool collective);
  template <int B>
  void prepare_own(Level<B>& level, std::size_t next, bool collective, bool refresh);
  template <int B>
  void cycle(Level<B>& level, std::size_t next, const Eigen::VectorXd& b, Eigen::VectorXd& x,
             bool collective);
  template <int B>
  void coarse_correction(Level<B>& level, std::size_t next, const Eigen::VectorXd& x,
                         bool collective);
  void decide_refresh();
  void improve_candidates();
  void build_tentatives();

  MultigridSettings settings_;
  Level<3> fine_;
  std::vector<Level<kModes>> coarse_;
  bool prolongators_ready_ = false;
  // The refresh rule's state, written by one thread between barriers.
  bool refresh_ = true, refreshed_ = false;
  long long refreshes_ = 0;
  long long prepares_ = 0;
  int since_refresh_ = 0;         // prepares since the last refresh
  int cycles_ = 0;                // V-cycles since the last prepare (the last solve's)
  int cycles_after_refresh_ = 0;  // V-cycles of the solve right after the last refresh
  bool measure_next_ = false;     // the next prepare reads the yardstick
};

}  // namespace fem::ch10
