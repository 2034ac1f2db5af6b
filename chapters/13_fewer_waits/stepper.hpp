// Chapter 13: fewer waits. Chapter 12's step, with its float V-cycle run in fewer parallel
// loops (fused_v_cycle.hpp) inside a PCG with one wait per reduction (single_reduction_pcg.hpp):
// every loop ends at a barrier where each thread waits for the slowest, and a loop whose work
// reads only its own rows can run inside the loop before it.
#pragma once

#include "chapters/12_half_the_bytes/stepper.hpp"
#include "chapters/13_fewer_waits/fused_v_cycle.hpp"
#include "chapters/13_fewer_waits/single_reduction_pcg.hpp"

namespace fem::ch13 {

class FewerWaitsStepper final : public ch12::HalfBytesStepper {
 public:
  FewerWaitsStepper(const Scene& scene, const SolverSettings& settings,
                    const ch10::MultigridStepperSettings& multigrid = {});

  ch09::Preconditioner& fused_v_cycle() { return fused_; }

 private:
  // Chronopoulos and Gear's PCG on the fused cycle (chapter 09's PCG where the hierarchy has
  // nothing to fuse: one level, or a finest level on one thread).
  SolveStats solve_filtered_system(Eigen::VectorXd& y) override;

  FusedVCycle fused_;
  SingleReductionPcg single_reduction_;
};

}  // namespace fem::ch13
