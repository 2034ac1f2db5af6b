#include "chapters/14_every_lane/work.hpp"

#include <algorithm>

#include "chapters/09_threads/parallel.hpp"
#include "chapters/10_multigrid/smoothers.hpp"
#include "chapters/10_multigrid/work.hpp"
#include "chapters/12_half_the_bytes/work.hpp"

namespace fem::ch14 {

namespace {

// The finest level's matrix as chapter 10 counts a level's (work.cpp, level_product): 3x3
// blocks of float, an index a block and a start a row.
template <class Fine>
double float_blocks_bytes(const Fine& fine) {
  const double blocks = double(fine.blocks.blocks()), rows = fine.blocks.rows();
  return 9.0 * sizeof(float) * blocks + 4.0 * (blocks + rows + 1);
}

}  // namespace

ch08::ElementWork element_work(const LaneScatterPass&, const ch08::WorkInput& in) {
  return ch08::fused_pass_work(in);
}

ExecutedWork element_counters(const LaneScatterPass& part, double elements) {
  return ch12::batch_counters(part.batched_elements(), elements);
}

ch08::PreconditionerWork preconditioner_work(const LaneMultigrid& part, const ch08::WorkInput& in) {
  ch08::PreconditionerWork w = ch10::multigrid_work(part.multigrid(), in, sizeof(float), true);
  const LaneVCycle& cycle = part.lane_v_cycle();
  if (!cycle.lanes()) return w;
  // Per pass of the level: the padding lanes (padded) and an offset a block (both).
  const double more = cycle.with_fine_level(
      [](const auto& fine) { return fine.blocks.bytes() - float_blocks_bytes(fine); });
  const double lanes_bytes =
      cycle.with_fine_level([](const auto& fine) { return fine.blocks.bytes(); });
  const double blocks =
      cycle.with_fine_level([](const auto& fine) { return double(fine.blocks.blocks()); });
  const double times = ch10::smoother_products(part.multigrid());
  PhaseWork apply;
  apply.phase = w.apply.phase;
  apply.working_set = w.apply.working_set + more;
  for (PhaseWork p : w.apply.parts) {
    if (p.phase == "level 0 smoothing and residual") {
      p.bytes_read += times * more;
      p.working_set += more;
    }
    apply.add_part(p, 1.0);
  }
  w.apply = apply;
  // Every step the finest level's double blocks read once more, and the lanes written.
  w.prepare_read += 9.0 * sizeof(double) * blocks;
  w.prepare_written += lanes_bytes;
  return w;
}

std::vector<PartKernel> preconditioner_kernels(LaneMultigrid& part, const ch08::KernelInput& in) {
  LaneVCycle& cycle = part.lane_v_cycle();
  if (!cycle.lanes()) return {};
  return cycle.with_fine_level([&](auto& fine) {
    const int step = std::min(1, ch10::smoothing_steps(fine) - 1);
    std::vector<PartKernel> kernels{ch09::part_kernel(
        "fine smoothing step (float, pair lanes)", "level 0 smoothing and residual",
        fine.smoothing_work(), in.passes * ch10::smoother_products(part.multigrid()),
        [&fine, step] {
          auto& v = fine.vectors;
          ch09::for_parts(source_level(fine).rows.part, true, [&](int first, int last) {
            smooth_rows(fine, step, first, last, v.b, &v.x, v.y);
          });
        })};
    // Below it, chapter 12's levels: the fine level's transfers, the coarse levels.
    for (PartKernel& k : ch12::below_fine_kernels(fine, part.reduced().v_cycle().coarse_levels(),
                                                  part.multigrid(), true, in))
      kernels.push_back(std::move(k));
    kernels.push_back(ch12::entry_and_exit_kernel(source_level(fine).rows.part, in));
    return kernels;
  });
}

}  // namespace fem::ch14
