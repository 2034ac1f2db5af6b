// Chapter 13: chapter 12's step with the fused V-cycle as the PCG's preconditioner (see
// stepper.hpp).
#include "chapters/13_fewer_waits/stepper.hpp"

namespace fem::ch13 {

namespace {

// Chapter 12's float V-cycle (the default arithmetic): its levels and their conversion.
ch12::ReducedVCycle<float>& float_v_cycle(ch12::HalfBytesStepper& stepper) {
  return dynamic_cast<ch12::ReducedVCycle<float>&>(stepper.v_cycle());
}

}  // namespace

FewerWaitsStepper::FewerWaitsStepper(const Scene& scene, const SolverSettings& settings,
                                     const ch10::MultigridStepperSettings& multigrid)
    : HalfBytesStepper(scene, settings, ch12::Arithmetic::single, multigrid),
      fused_(float_v_cycle(*this), this->multigrid()) {
  use_preconditioner(fused_, "13_fewer_waits");
}

}  // namespace fem::ch13
