// Chapter 13's parts: chapter 12's float V-cycle run in fewer parallel loops (fused_v_cycle.hpp),
// inside a PCG with one wait per reduction (single_reduction_pcg.hpp): every loop ends at a
// barrier where each thread waits for the slowest, and a loop whose work reads only its own
// rows can run inside the loop before it.
#pragma once

#include <ostream>

#include "chapters/08_element_kernels/step.hpp"
#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/12_half_the_bytes/parts.hpp"
#include "chapters/13_fewer_waits/fused_v_cycle.hpp"
#include "chapters/13_fewer_waits/single_reduction_pcg.hpp"

namespace fem::ch13 {

// Preconditioner: chapter 12's float hierarchy, its cycle run by fused loops.
class FusedPreconditioner {
 public:
  using Params = ch10::MultigridSettings;
  static constexpr const char* kName = "one V-cycle on float numbers, its loops fused";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  FusedPreconditioner(const ch08::PartSetup& setup, const Params& params)
      : reduced_(setup, params), fused_(reduced_.v_cycle(), reduced_.multigrid()) {}
  ch09::Preconditioner& pcg_preconditioner() { return fused_; }
  FusedVCycle& fused_v_cycle() { return fused_; }
  ch12::ReducedMultigrid<float>& reduced() { return reduced_; }
  ch10::Multigrid& multigrid() { return reduced_.multigrid(); }
  const ch10::Multigrid& multigrid() const { return reduced_.multigrid(); }
  void describe(std::ostream& out) const { reduced_.describe(out); }

 private:
  ch12::ReducedMultigrid<float> reduced_;  // chapter 12's levels and their conversion
  FusedVCycle fused_;                      // reads reduced_: declared after it
};

// Solver: Chronopoulos and Gear's PCG on the fused cycle (chapter 09's PCG where the hierarchy
// has nothing to fuse: one level, or a finest level on one thread).
class SingleReductionSolver {
 public:
  static constexpr const char* kName = "single-reduction PCG (Chronopoulos and Gear)";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  SingleReductionSolver(const ch08::PartSetup& setup, FusedPreconditioner& preconditioner)
      : single_reduction_(preconditioner.fused_v_cycle().fine_part(), setup.scene.constraints),
        parallel_(setup.system.A, setup.scene.constraints) {}
  SolveStats solve(ch08::System& system, FusedPreconditioner& preconditioner,
                   const SolverSettings& settings) {
    FusedVCycle& M = preconditioner.fused_v_cycle();
    if (!M.fused()) return parallel_.solve(system.A, M, system.filtered_b, settings, system.y);
    return single_reduction_.solve(system.A, M, system.filtered_b, settings, system.y);
  }
  void set_constraints(const std::vector<NodeConstraint>& constraints) {
    single_reduction_.set_constraints(constraints);
    parallel_.set_constraints(constraints);
  }
  SingleReductionPcg& single_reduction() { return single_reduction_; }

 private:
  SingleReductionPcg single_reduction_;
  ch09::ParallelPcg parallel_;  // where nothing is fused
};

}  // namespace fem::ch13
