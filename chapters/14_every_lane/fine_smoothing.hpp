// The V-cycle's finest level in float with its products in the lanes of row pairs
// (row_pairs.hpp): the polynomial smoothing step and the residual, which the V-cycle runs on
// it some twelve times per cycle, and which alone took two thirds of a step with a quarter of
// the lanes busy.
//
// A part for a stepper: a level type of the V-cycle (v_cycle.hpp's interface, found by
// argument-dependent lookup) that views a float level (its inverse diagonal, weights and
// vectors stay that level's) and holds the level's matrix in its own layout. In the product
// the same multiply-adds per lane in the same order as the padded columns: the residual is
// theirs to the bit; the smoothing step's update rounds once where the compiler chooses (see
// smooth_rows), within a float epsilon of its terms.
#pragma once

#include <Eigen/Core>

#include "chapters/10_multigrid/smoothers.hpp"
#include "chapters/12_half_the_bytes/reduced_kernels.hpp"
#include "chapters/12_half_the_bytes/reduced_v_cycle.hpp"
#include "chapters/14_every_lane/row_pairs.hpp"
#include "chapters/work.hpp"

namespace fem::ch14 {

using FloatLevel = ch12::ReducedLevel<float, 3>;
using CoarseFloatLevel = ch12::ReducedLevel<float, ch10::kModes>;

struct LaneFineLevel : ch10::PolynomialLevel {
  static constexpr int block_size = 3;

  // The layout of the level's pattern in its row blocks (set-up); the level must outlive
  // this object.
  explicit LaneFineLevel(FloatLevel& level)
      : level(level),
        smoother(level.smoother),
        vectors(level.vectors),
        blocks(level.source->A, level.source->rows.part) {}

  // The level's double values (its source's) into the lanes, rows [first, last) of whole
  // row blocks: after each factorization, by every thread on its row blocks. Rounded to
  // float as the float level's are.
  void fill(int first, int last) { blocks.fill(level.source->values, first, last); }

  // One call over every row: bytes and flops (float) as chapters/work.hpp counts them.
  PhaseWork smoothing_work() const;
  PhaseWork residual_work() const;

  FloatLevel& level;
  decltype(FloatLevel::smoother)& smoother;  // the V-cycle reads the weights here
  ch10::WorkVectors<float>& vectors;
  RowPairBlocks blocks;
};

// Step k of the polynomial smoother on rows [first, last) of whole row blocks (from zero when
// in is null): out and the level's direction written on those rows; every row of in must be
// written before.
void smooth_rows(LaneFineLevel& level, int k, int first, int last, const Eigen::VectorXf& b,
                 const Eigen::VectorXf* in, Eigen::VectorXf& out);
// b - A x on rows [first, last) of whole row blocks, into the level's residual vector.
void residual_rows(LaneFineLevel& level, int first, int last, const Eigen::VectorXf& b,
                   const Eigen::VectorXf& x);

// ---- the level's kernels for the V-cycle (argument-dependent lookup) ---------------------

// The V-cycle's smooth and residual on this level: the functions above (better matches than
// the V-cycle's generic ones for every polynomial level).
inline void smooth(LaneFineLevel& level, int k, int first, int last, const Eigen::VectorXf& b,
                   const Eigen::VectorXf* in, Eigen::VectorXf& out, bool /*forward*/) {
  smooth_rows(level, k, first, last, b, in, out);
}
inline void residual(LaneFineLevel& level, int first, int last, const Eigen::VectorXf& b,
                     const Eigen::VectorXf& x) {
  residual_rows(level, first, last, b, x);
}

inline const ch10::Level<3>& source_level(const LaneFineLevel& level) {
  return *level.level.source;
}

template <class Rhs>
EIGEN_ALWAYS_INLINE Eigen::Vector3f times_inverse_diagonal(const LaneFineLevel& level, int i,
                                                           const Rhs& r) {
  return ch12::times_inverse_diagonal(level.level, i, r);
}

// The transfers and the coarsest solve are the float level's.
inline void restrict_rows(const LaneFineLevel& level, CoarseFloatLevel& coarse, int first,
                          int last) {
  ch12::restrict_rows(level.level, coarse, first, last);
}
inline void prolong_rows(LaneFineLevel& level, const CoarseFloatLevel& coarse, int first, int last,
                         const Eigen::VectorXf& x) {
  ch12::prolong_rows(level.level, coarse, first, last, x);
}
inline void solve_coarsest(LaneFineLevel& level, const Eigen::VectorXf& b, Eigen::VectorXf& out) {
  ch12::solve_coarsest(level.level, b, out);
}

}  // namespace fem::ch14
