// Chapter 13: chapter 12's step with the fused V-cycle inside the single-reduction PCG (see
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
      fused_(float_v_cycle(*this), this->multigrid()),
      single_reduction_(fused_.fine_part(), scene_.constraints) {
  use_preconditioner(fused_, "13_fewer_waits");
}

SolveStats FewerWaitsStepper::solve_filtered_system(Eigen::VectorXd& y) {
  if (!fused_.fused()) return HalfBytesStepper::solve_filtered_system(y);
  return single_reduction_.solve(system_matrix(), fused_, system_rhs(), settings_, y);
}

}  // namespace fem::ch13
