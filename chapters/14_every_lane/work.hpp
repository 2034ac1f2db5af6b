// This chapter's part's work (chapters/08_element_kernels/work.hpp: counted part by part):
// chapter 12's float V-cycle, but the finest level's products read the pair lanes' layout
// (its bytes, padding included) instead of the 3x3 float blocks, and every step fills it.
#pragma once

#include <vector>

#include "chapters/08_element_kernels/work.hpp"
#include "chapters/09_threads/work.hpp"
#include "chapters/12_half_the_bytes/work.hpp"
#include "chapters/14_every_lane/lane_product.hpp"
#include "chapters/14_every_lane/parts.hpp"

namespace fem::ch14 {

// The element pass: chapter 12's (the prefetches add no bytes, only fetch them sooner).
ch08::ElementWork element_work(const LaneScatterPass& part, const ch08::WorkInput& in);
ExecutedWork element_counters(const LaneScatterPass& part, double elements);

ch08::PreconditionerWork preconditioner_work(const LaneMultigrid& part, const ch08::WorkInput& in);

// The product in pair lanes: its layout's bytes (padding included) a pass, 18 flops a block;
// every solve A's double blocks read once more and the lanes written.
template <bool Packed>
ch08::ProductWork product_work(const PairProduct<Packed>& part, const ch07::BlockSparseMatrix& A) {
  const double blocks = double(part.blocks().blocks());
  return {part.blocks().bytes(), 18.0 * blocks, 9.0 * sizeof(double) * double(A.blocks.size()),
          part.blocks().bytes()};
}

// Its own kernel alone: the finest level's smoothing step in pair lanes (a step after the
// first, as chapter 12's is timed).
std::vector<PartKernel> preconditioner_kernels(LaneMultigrid& part, const ch08::KernelInput& in);

}  // namespace fem::ch14
