// This chapter's parts' work (chapters/08_element_kernels/work.hpp: counted part by part): the
// batched pass computes the fused pass's terms, a batch at a time; the V-cycle's levels in
// float, its arithmetic in float or in double as the part says.
#pragma once

#include <algorithm>
#include <string>
#include <type_traits>
#include <vector>

#include "chapters/08_element_kernels/work.hpp"
#include "chapters/09_threads/work.hpp"
#include "chapters/10_multigrid/work.hpp"
#include "chapters/12_half_the_bytes/parts.hpp"
#include "chapters/12_half_the_bytes/reduced_kernels.hpp"

namespace fem::ch12 {

ch08::ElementWork element_work(const BatchedElementPass& part, const ch08::WorkInput& in);
// The batched pass's counters: rotations, Newton's iterations (every lane of a batch runs the
// batch's), fallbacks.
ExecutedWork element_counters(const BatchedElementPass& part, double elements);
// The same of any part that runs the batches (chapter 14's too).
ExecutedWork batch_counters(const BatchedElements& batched, double elements);

template <class Real>
ch08::PreconditionerWork preconditioner_work(const ReducedMultigrid<Real>& part,
                                             const ch08::WorkInput& in) {
  return ch10::multigrid_work(part.multigrid(), in, sizeof(float), std::is_same_v<Real, float>);
}

// The fine level's smoothing step of the float V-cycle alone (chapter 10's polynomial step, a
// step after the first: it reads x, b and the direction and writes y and the direction),
// counted as chapter 10 counts one of the level's products; smoother_products of them per
// V-cycle. None where the hierarchy has one level.
template <class Real>
std::vector<PartKernel> smoothing_kernels(ReducedVCycle<Real>& cycle,
                                          const ch10::Multigrid& multigrid,
                                          const ch08::KernelInput& in) {
  if (multigrid.levels() < 2) return {};
  const std::vector<ch10::LevelSize> levels = ch10::multigrid_levels(multigrid);
  PhaseWork one =
      ch10::v_cycle_work({levels.front()}, 1, sizeof(float), std::is_same_v<Real, float>)
          .parts.front();
  const std::string part = one.phase;
  one.phase = "smoothing step";
  auto& fine = cycle.fine_level();
  const int step = std::min(1, ch10::smoothing_steps(fine) - 1);
  return {ch09::part_kernel(
      std::is_same_v<Real, float> ? "fine smoothing step (float)"
                                  : "fine smoothing step (double on float)",
      part, one, in.passes * ch10::smoother_products(multigrid), [&fine, step] {
        ch09::for_parts(source_level(fine).rows.part, true, [&](int first, int last) {
          ch10::smooth(fine, step, first, last, fine.vectors.b, &fine.vectors.x, fine.vectors.y,
                       true);
        });
      })};
}

template <class Real>
std::vector<PartKernel> preconditioner_kernels(ReducedMultigrid<Real>& part,
                                               const ch08::KernelInput& in) {
  return smoothing_kernels(part.v_cycle(), part.multigrid(), in);
}

}  // namespace fem::ch12
