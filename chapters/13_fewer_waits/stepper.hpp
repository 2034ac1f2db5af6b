// Chapter 13: fewer waits. Chapter 12's step, with its float V-cycle run in fewer parallel
// loops (fused_v_cycle.hpp): every loop ends at a barrier where each thread waits for the
// slowest, and a loop whose work reads only its own rows can run inside the loop before it.
// The same numbers, the same sums in the same order: chapter 12's state, to the bit.
#pragma once

#include "chapters/12_half_the_bytes/stepper.hpp"
#include "chapters/13_fewer_waits/fused_v_cycle.hpp"

namespace fem::ch13 {

class FewerWaitsStepper final : public ch12::HalfBytesStepper {
 public:
  FewerWaitsStepper(const Scene& scene, const SolverSettings& settings,
                    const ch10::MultigridStepperSettings& multigrid = {});

  ch09::Preconditioner& fused_v_cycle() { return fused_; }

 private:
  FusedVCycle fused_;
};

}  // namespace fem::ch13
