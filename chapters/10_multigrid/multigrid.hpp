// Chapter 10: smoothed-aggregation algebraic multigrid (Vanek, Mandel & Brezina 1996) on 3x3
// block matrices, as the preconditioner of the PPCG solve (Tamstorf, Jones & McCormick 2015,
// the poster's reference for its constraint method): the hierarchy that wires the stages
// (aggregation.hpp, near_null_space.hpp, prolongator.hpp, galerkin.hpp, smoothers.hpp,
// level.hpp, refresh_rule.hpp, v_cycle.hpp).
//
// The split that makes it cheap enough to run every step, named as Eigen names its
// preconditioners' (IterativeLinearSolvers/IncompleteCholesky.h: analyzePattern, factorize,
// solve):
//  - analyze_pattern: everything that depends only on the mesh (aggregates, the tentative
//    prolongator from the rigid-body modes, the patterns of the smoothed prolongator and of
//    every Galerkin product P^T A P, tables that say where each block product lands, and a
//    FIXED partition of every level's rows into blocks), once;
//  - factorize: numbers only, on those fixed patterns, once per step;
//  - apply: one V-cycle, once per PCG iteration.
// Neither factorize nor apply allocates.
//
// Both run on every thread of the caller's OpenMP team: every loop is shared out like an
// orphaned `omp for` (chapter 09's StaticShare) over the level's fixed row blocks, every sum runs
// in a fixed order, so the result is the same to the last bit for any thread count. Called outside
// a parallel region, they run on the calling thread alone.
//
// The multigrid knows nothing of the stepper: it reads the fine matrix as block compressed
// rows (row_start, column, blocks), the layout of chapter 07's BlockSparseMatrix.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "chapters/10_multigrid/level.hpp"
#include "chapters/10_multigrid/refresh_rule.hpp"
#include "chapters/10_multigrid/smoothers.hpp"
#include "chapters/10_multigrid/v_cycle.hpp"
#include "common/scene.hpp"

namespace fem::ch10 {

// AMGCL's `coarsening` parameters: how each level's coarse space is built.
struct CoarseningSettings {
  // Modes per aggregate: 6 (3 translations, 3 rotations) or 3 (translations only). The
  // coarse blocks stay 6 x 6; missing modes become identity rows, as constrained dofs do.
  int modes = kModes;
  // Sweeps of symmetric Gauss-Seidel on A B = 0 that improve the rigid-body modes B on the
  // first matrix before T is built (PyAMG's improve_candidates); 0: the modes as they are.
  int improve_candidates = 4;
  bool smooth_prolongator = true;   // P = (I - w D^-1 A) T; false: P = T (plain aggregation)
  bool update_prolongator = false;  // smooth P at every refresh (default: on the first)
  // The first estimate of rho(D^-1 A) on each level, for the prolongator's weight and the
  // Chebyshev bound. Power iteration approaches rho from below, slowly where the top of the
  // spectrum is crowded (a fine mesh), and a low bound amplifies the eigenvalues above it:
  // `fem_lessons multigrid --power N` measures the iterations it costs.
  int power_iterations = 30;
};

struct MultigridSettings {
  CoarseningSettings coarsening;
  SmootherSettings relax;
  RowBlockSettings rows;
  RefreshSettings refresh;
  int max_levels = 8;
  int max_coarse_dofs = 200;  // the dense Cholesky's size limit
};

// The settings' one check, run by the constructors (Multigrid's, the steppers' through
// check(MultigridStepperSettings)); the lesson's command line turns it into a usage error.
// Throws std::invalid_argument naming what is out of range.
void check(const MultigridSettings& settings);

struct Coarsening;  // the set-up data (coarsening.hpp)

class Multigrid {
 public:
  explicit Multigrid(const MultigridSettings& settings = {});
  ~Multigrid();
  Multigrid(const Multigrid&) = delete;
  Multigrid& operator=(const Multigrid&) = delete;

  // Set-up from the fine pattern (block compressed rows, the diagonal included), the rest
  // positions X (3N) for the rigid-body modes and the constraints (the filter S_i of each
  // constrained node removes its constrained directions from the near-null space).
  void analyze_pattern(const std::vector<int>& row_start, const std::vector<int>& column,
                       const Eigen::VectorXd& rest_positions,
                       const std::vector<NodeConstraint>& constraints);
  // The constraints changed while the body runs: the modes filtered by the new ones, and the
  // next factorize sets the prolongators up on its matrix as the first one did (a refresh).
  // P smoothed on a matrix without these constraints keeps, in the coarse space, directions
  // they took away: a plate landing flat on a floor (964 of its 2069 nodes held at once, one
  // step after a free one) then took 350 iterations a solve in chapter 11 and never converged
  // in chapters 12-14 (tests/chapters/ch10_multigrid.cpp). Only the constrained nodes and
  // directions count: a drag, which changes their velocities, sets nothing up again.
  void set_constraints(const std::vector<NodeConstraint>& constraints);
  // The numbers of this step's filtered matrix (same pattern as at set-up): the smoothers
  // of the finest level; at a refresh also the coarse matrices, their smoothers, the
  // Cholesky factor (and the prolongators the first time). The blocks must stay alive and
  // unchanged until the last apply(). Called by every thread of a team, or outside one.
  void factorize(const std::vector<Eigen::Matrix3d>& fine_blocks);
  // z = M r, one V-cycle from a zero guess: symmetric, positive definite. Called by every
  // thread of a team (r complete before the call), or outside one.
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z);

  // The same two rules for levels of another type that copy this hierarchy's with other
  // numbers (chapter 12's float levels), which bring only their kernels (v_cycle.hpp):
  // after factorize(), update(level, collective, refreshed) on the levels it changed, the
  // finest every time, the coarse ones after a refresh (all of them when `all`), a small level
  // and those below it on one thread; and one V-cycle on them, counted by the refresh rule.
  // Same calling rules as factorize() and apply().
  template <class Fine, class Coarse, class Update>
  void for_factorized_levels(Fine& fine, std::vector<Coarse>& coarse, bool all, Update&& update) {
    const bool refreshed = all || refresh_rule_.refreshed();
    auto work = [&](auto& level, std::size_t, bool collective) {
      update(level, collective, refreshed);
    };
    for_levels_from(fine, coarse, 0, true, refreshed, work);
  }
  template <class Fine, class Coarse, class Vector>
  void apply(Fine& fine, std::vector<Coarse>& coarse, const Vector& r, Vector& z) {
    refresh_rule_.count_cycle();
    v_cycle(fine, coarse, 0, r, z, true);
  }

  const MultigridSettings& settings() const { return settings_; }
  // The levels as factorize() left them (level 0: the mesh).
  int levels() const { return 1 + static_cast<int>(coarse_.size()); }
  const Level<3>& fine_level() const { return fine_; }
  const std::vector<Level<kModes>>& coarse_levels() const { return coarse_; }
  // Counts the V-cycles (apply's, and any cycle run on these levels outside it) for the rule.
  RefreshRule& refresh_rule() { return refresh_rule_; }
  const RefreshRule& refresh_rule() const { return refresh_rule_; }

  // For the lesson's costs per level: factorize()'s own work on one level (as at a refresh,
  // or as between refreshes), and one V-cycle from `level` down on the level's own b. Same
  // calling rules as factorize() and apply(); after a first factorize().
  void factorize_level(int level, bool refresh);
  void cycle_from(int level);

 private:
  template <int B>
  void factorize_own(Level<B>& level, std::size_t next, bool collective, bool refresh);
  template <int B>
  void estimate_spectrum(Level<B>& level, bool new_prolongator);
  void finish_set_up();
  void build_tentatives();

  MultigridSettings settings_;
  Level<3> fine_;
  std::vector<Level<kModes>> coarse_;
  std::unique_ptr<Coarsening> coarsening_;  // the aggregates kept: set_constraints builds P again
  bool prolongators_ready_ = false;
  Eigen::VectorXd rest_positions_;                 // the modes' positions
  std::vector<NodeConstraint> modes_constraints_;  // the constraints the modes were filtered by
  RefreshRule refresh_rule_;
};

}  // namespace fem::ch10
