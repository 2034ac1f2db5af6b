// The V-cycle's finest level in float with its products in vector lanes filled across blocks:
// the polynomial smoothing step and the residual, which the V-cycle runs on it some twelve
// times per cycle, and which alone took two thirds of a step with a quarter of the lanes busy.
// The step runs a row's blocks in pairs (paired_blocks.hpp, 256-bit registers). The course
// measures a second layout beside it, two rows' pairs side by side (row_pairs.hpp, 512-bit
// registers, three 128-bit inserts and three permutes of 512 bits per four blocks): on the AMD
// EPYC this was measured on (family 26 by its cpuid: Zen 5) the pairs are the faster by far
// (lanes_bench); measure on other cores.
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
#include "chapters/14_every_lane/paired_blocks.hpp"
#include "chapters/work.hpp"

namespace fem::ch14 {

using FloatLevel = ch12::ReducedLevel<float, 3>;
using CoarseFloatLevel = ch12::ReducedLevel<float, ch10::kModes>;

// The layout of a level's pattern.
using PaddedFloatBlocks = PairedBlocks<float, false>;
inline PaddedFloatBlocks lanes_of(const ch10::Level<3>& level, const PaddedFloatBlocks*) {
  return PaddedFloatBlocks(level.A);
}
using PackedFloatBlocks = PairedBlocks<float, true>;
inline PackedFloatBlocks lanes_of(const ch10::Level<3>& level, const PackedFloatBlocks*) {
  return PackedFloatBlocks(level.A);
}

template <class Blocks>
struct LaneLevel : ch10::PolynomialLevel {
  static constexpr int block_size = 3;

  // The layout of the level's pattern (set-up); the level must outlive this object.
  explicit LaneLevel(FloatLevel& level)
      : level(level),
        smoother(level.smoother),
        vectors(level.vectors),
        blocks(lanes_of(*level.source, static_cast<const Blocks*>(nullptr))) {}

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
  Blocks blocks;
};
using LaneFineLevel = LaneLevel<PaddedFloatBlocks>;    // the pair lanes, padded
using PackedFineLevel = LaneLevel<PackedFloatBlocks>;  // the pair lanes, packed

// Step k of the polynomial smoother on rows [first, last) of whole row blocks (from zero when
// in is null): out and the level's direction written on those rows; every row of in must be
// written before.
template <class Blocks>
void smooth_rows(LaneLevel<Blocks>& level, int k, int first, int last, const Eigen::VectorXf& b,
                 const Eigen::VectorXf* in, Eigen::VectorXf& out);
// b - A x on rows [first, last) of whole row blocks, into the level's residual vector.
template <class Blocks>
void residual_rows(LaneLevel<Blocks>& level, int first, int last, const Eigen::VectorXf& b,
                   const Eigen::VectorXf& x);

// ---- the level's kernels for the V-cycle (argument-dependent lookup) ---------------------

// The V-cycle's smooth and residual on this level: the functions above (better matches than
// the V-cycle's generic ones for every polynomial level).
template <class Blocks>
inline void smooth(LaneLevel<Blocks>& level, int k, int first, int last, const Eigen::VectorXf& b,
                   const Eigen::VectorXf* in, Eigen::VectorXf& out, bool /*forward*/) {
  smooth_rows(level, k, first, last, b, in, out);
}
template <class Blocks>
inline void residual(LaneLevel<Blocks>& level, int first, int last, const Eigen::VectorXf& b,
                     const Eigen::VectorXf& x) {
  residual_rows(level, first, last, b, x);
}

template <class Blocks>
inline const ch10::Level<3>& source_level(const LaneLevel<Blocks>& level) {
  return *level.level.source;
}

template <class Blocks, class Rhs>
EIGEN_ALWAYS_INLINE Eigen::Vector3f times_inverse_diagonal(const LaneLevel<Blocks>& level, int i,
                                                           const Rhs& r) {
  return ch12::times_inverse_diagonal(level.level, i, r);
}

// The transfers and the coarsest solve are the float level's.
template <class Blocks>
inline void restrict_rows(const LaneLevel<Blocks>& level, CoarseFloatLevel& coarse, int first,
                          int last) {
  ch12::restrict_rows(level.level, coarse, first, last);
}
template <class Blocks>
inline void prolong_rows(LaneLevel<Blocks>& level, const CoarseFloatLevel& coarse, int first,
                         int last, const Eigen::VectorXf& x) {
  ch12::prolong_rows(level.level, coarse, first, last, x);
}
template <class Blocks>
inline void solve_coarsest(LaneLevel<Blocks>& level, const Eigen::VectorXf& b,
                           Eigen::VectorXf& out) {
  ch12::solve_coarsest(level.level, b, out);
}

}  // namespace fem::ch14
