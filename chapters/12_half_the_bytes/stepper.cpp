// Chapter 12: chapter 11's step, its V-cycle on float numbers (see stepper.hpp).
#include "chapters/12_half_the_bytes/stepper.hpp"

namespace fem::ch12 {

namespace {

std::unique_ptr<ch09::Preconditioner> reduced_v_cycle(ch10::Multigrid& multigrid,
                                                      Arithmetic arithmetic) {
  if (arithmetic == Arithmetic::single) return std::make_unique<ReducedVCycle<float>>(multigrid);
  return std::make_unique<ReducedVCycle<double>>(multigrid);
}

}  // namespace

HalfBytesStepper::HalfBytesStepper(const Scene& scene, const SolverSettings& settings,
                                   Arithmetic arithmetic, const ch10::MultigridSettings& multigrid)
    : NodeOrderStepper(scene, settings, ch11::Ordering::rcm, multigrid),
      arithmetic_(arithmetic),
      v_cycle_(reduced_v_cycle(this->multigrid(), arithmetic)) {
  // Chapter 10's hierarchy, set up and prepared in double as before; the PCG now applies it
  // through the float copy.
  use_preconditioner(*v_cycle_, "12_half_the_bytes");
}

}  // namespace fem::ch12
